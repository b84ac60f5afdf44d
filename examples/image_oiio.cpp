/* Texture decoding with OpenImageIO. */
#include "image.h"

#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <cstdlib>
#include <string>

static int image_fail(const char *path, const std::string &why, char *err, size_t err_size) {
    if (err_size) {
        std::string line = why.substr(0, why.find('\n')); // keep messages one line
        std::snprintf(err, err_size, "%s: %s", path, line.c_str());
    }
    return 0;
}

extern "C" int vdag_image_load(const char *path, vdag_image *out, char *err, size_t err_size) {
    out->width = out->height = 0;
    out->rgb = NULL;
    try {
        auto in = OIIO::ImageInput::open(path);
        if (!in) return image_fail(path, OIIO::geterror(), err, err_size);
        const OIIO::ImageSpec &spec = in->spec();
        if (spec.width <= 0 || spec.height <= 0 || spec.depth != 1 || spec.nchannels <= 0)
            return image_fail(path, "not a 2D image", err, err_size);
        uint64_t pixels = (uint64_t)spec.width * (uint64_t)spec.height;
        if (pixels > VDAG_IMAGE_MAX_PIXELS)
            return image_fail(path, "image too large", err, err_size);
        // Grey (and grey + alpha) images are read as one channel, then widened.
        int channels = spec.nchannels >= 3 ? 3 : 1;
        uint8_t *rgb = static_cast<uint8_t *>(std::malloc((size_t)pixels * 3));
        if (!rgb) return image_fail(path, "out of memory", err, err_size);
        if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, rgb)) {
            std::free(rgb);
            return image_fail(path, in->geterror(), err, err_size);
        }
        if (channels == 1)
            for (size_t i = (size_t)pixels; i-- > 0;) rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = rgb[i];
        out->width = (uint32_t)spec.width;
        out->height = (uint32_t)spec.height;
        out->rgb = rgb;
        return 1;
    } catch (...) {
        return image_fail(path, "image decoder failed", err, err_size);
    }
}

extern "C" void vdag_image_free(vdag_image *image) {
    if (!image) return;
    std::free(image->rgb);
    image->rgb = NULL;
    image->width = image->height = 0;
}
