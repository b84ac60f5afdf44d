/* Mean structural similarity (SSIM, Wang et al. 2004) of two pictures of the
   same size, for bench/image_quality.sh: luma (Rec. 601 weights) of binary
   PPMs, 11x11 Gaussian window with sigma 1.5, K1 = 0.01, K2 = 0.03, L = 255,
   averaged over the windows that lie inside the picture. Prints the mean.
     ssim A.ppm B.ppm */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define R 5 /* window radius */

static float *read_luma(const char *path, unsigned *w, unsigned *h) {
    FILE *f = fopen(path, "rb");
    unsigned maxval;
    size_t i, n;
    unsigned char *rgb;
    float *y;
    if (!f || fscanf(f, "P6 %u %u %u", w, h, &maxval) != 3 || maxval != 255 || fgetc(f) == EOF || !*w || !*h ||
        *w > 16384 || *h > 16384) {
        fprintf(stderr, "ssim: %s: not a binary 8-bit PPM\n", path);
        exit(1);
    }
    n = (size_t)*w * *h;
    rgb = (unsigned char *)malloc(3 * n);
    y = (float *)malloc(n * sizeof *y);
    if (!rgb || !y || fread(rgb, 3, n, f) != n) {
        fprintf(stderr, "ssim: %s: truncated or out of memory\n", path);
        exit(1);
    }
    fclose(f);
    for (i = 0; i < n; i++) y[i] = 0.299f * rgb[3 * i] + 0.587f * rgb[3 * i + 1] + 0.114f * rgb[3 * i + 2];
    free(rgb);
    return y;
}

/* OUT = IN filtered by the separable Gaussian G, rows then columns; only the
   rows and columns at least R from the border are valid. */
static void blur(const float *in, float *out, float *tmp, unsigned w, unsigned h, const double g[2 * R + 1]) {
    unsigned x, y;
    int k;
    for (y = 0; y < h; y++)
        for (x = R; x + R < w; x++) {
            double s = 0;
            for (k = -R; k <= R; k++) s += g[k + R] * in[(size_t)y * w + x + k];
            tmp[(size_t)y * w + x] = (float)s;
        }
    for (y = R; y + R < h; y++)
        for (x = R; x + R < w; x++) {
            double s = 0;
            for (k = -R; k <= R; k++) s += g[k + R] * tmp[(size_t)(y + k) * w + x];
            out[(size_t)y * w + x] = (float)s;
        }
}

int main(int argc, char **argv) {
    unsigned w, h, w2, h2, x, y;
    float *a, *b, *m[5], *in, *tmp;
    double g[2 * R + 1], gs = 0, sum = 0, c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
    size_t i, n;
    int k;
    if (argc != 3) {
        fprintf(stderr, "usage: ssim A.ppm B.ppm\n");
        return 2;
    }
    a = read_luma(argv[1], &w, &h);
    b = read_luma(argv[2], &w2, &h2);
    if (w != w2 || h != h2 || w <= 2 * R || h <= 2 * R) {
        fprintf(stderr, "ssim: the pictures differ in size or are smaller than the window\n");
        return 1;
    }
    for (k = -R; k <= R; k++) gs += g[k + R] = exp(-(double)(k * k) / (2 * 1.5 * 1.5));
    for (k = 0; k <= 2 * R; k++) g[k] /= gs;
    n = (size_t)w * h;
    in = (float *)malloc(n * sizeof *in);
    tmp = (float *)calloc(n, sizeof *tmp);
    for (k = 0; k < 5; k++) m[k] = (float *)calloc(n, sizeof *m[k]);
    if (!in || !tmp || !m[0] || !m[1] || !m[2] || !m[3] || !m[4]) {
        fprintf(stderr, "ssim: out of memory\n");
        return 1;
    }
    /* Local means of a, b, a^2, b^2 and ab. */
    for (k = 0; k < 5; k++) {
        for (i = 0; i < n; i++) in[i] = k == 0 ? a[i] : k == 1 ? b[i] : k == 2 ? a[i] * a[i] : k == 3 ? b[i] * b[i] : a[i] * b[i];
        blur(in, m[k], tmp, w, h, g);
    }
    for (y = R; y + R < h; y++)
        for (x = R; x + R < w; x++) {
            size_t j = (size_t)y * w + x;
            double ma = m[0][j], mb = m[1][j];
            double va = m[2][j] - ma * ma, vb = m[3][j] - mb * mb, cov = m[4][j] - ma * mb;
            sum += (2 * ma * mb + c1) * (2 * cov + c2) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
        }
    printf("%.5f\n", sum / ((double)(w - 2 * R) * (h - 2 * R)));
    for (k = 0; k < 5; k++) free(m[k]);
    free(in);
    free(tmp);
    free(a);
    free(b);
    return 0;
}
