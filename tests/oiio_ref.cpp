// OpenImageIO as the independent reference for the tool's texture decoder
// (examples/image_stb.c): writes test images and decodes any image to RGBA.
#include "oiio_ref.h"

#include <OpenImageIO/imageio.h>

#include <cstdlib>
#include <cstring>

extern "C" int oiio_ref_load(const char *path, uint32_t *w, uint32_t *h, uint8_t **rgba) {
    *rgba = NULL;
    try {
        OIIO::ImageSpec config; // the file's own values, not alpha-premultiplied ones
        config.attribute("oiio:UnassociatedAlpha", 1);
        auto in = OIIO::ImageInput::open(path, &config);
        if (!in) return 0;
        const OIIO::ImageSpec &spec = in->spec();
        int c = spec.nchannels;
        if (spec.width <= 0 || spec.height <= 0 || c <= 0) return 0;
        size_t n = (size_t)spec.width * (size_t)spec.height;
        uint8_t *raw = static_cast<uint8_t *>(std::malloc(n * (size_t)c)), *out = static_cast<uint8_t *>(std::malloc(4 * n));
        if (!raw || !out || !in->read_image(0, 0, 0, c, OIIO::TypeDesc::UINT8, raw)) {
            std::free(raw);
            std::free(out);
            return 0;
        }
        int alpha = spec.alpha_channel >= 0 ? spec.alpha_channel : (c == 2 || c == 4 ? c - 1 : -1);
        for (size_t i = 0; i < n; i++) {
            const uint8_t *p = raw + i * (size_t)c;
            out[4 * i + 0] = p[0];
            out[4 * i + 1] = c >= 3 ? p[1] : p[0];
            out[4 * i + 2] = c >= 3 ? p[2] : p[0];
            out[4 * i + 3] = alpha >= 0 ? p[alpha] : 255;
        }
        std::free(raw);
        *w = (uint32_t)spec.width;
        *h = (uint32_t)spec.height;
        *rgba = out;
        return 1;
    } catch (...) {
        return 0;
    }
}

extern "C" int oiio_ref_write(const char *path, uint32_t w, uint32_t h, int channels, const uint8_t *pixels,
                              const char *compression) {
    try {
        auto out = OIIO::ImageOutput::create(path);
        if (!out) return 0;
        OIIO::ImageSpec spec((int)w, (int)h, channels, OIIO::TypeDesc::UINT8);
        if (channels == 2 || channels == 4) spec.alpha_channel = channels - 1;
        spec.attribute("oiio:UnassociatedAlpha", 1); // PIXELS go to the file as they are
        if (compression && *compression) spec.attribute("compression", compression);
        if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::UINT8, pixels)) return 0;
        return out->close() ? 1 : 0;
    } catch (...) {
        return 0;
    }
}
