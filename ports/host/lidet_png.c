/* SPDX-License-Identifier: MIT */
/* PNG writer of the host tools: 8-bit RGB. With libpng (Debian libpng-dev, found by CMake: LIDET_HAVE_LIBPNG)
 * the image is deflate-compressed with libpng's adaptive filters. Without it (CMake warns), a fallback
 * writes a valid but uncompressed file: filter 0, zlib stream of stored deflate blocks. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

#if LIDET_HAVE_LIBPNG
#include <png.h>

/* everything that can longjmp, outside the function holding the setjmp (no local is modified after it) */
static void png_emit(png_structp png, png_infop info, FILE *f, const uint8_t *rgb, uint32_t width, uint32_t height)
{
    uint32_t y;
    png_init_io(png, f);
    png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (y = 0; y < height; ++y)
    {
        png_write_row(png, (png_const_bytep)(rgb + (size_t)y * width * 3u));
    }
    png_write_end(png, NULL);
}

static int png_write_libpng(FILE *f, const uint8_t *rgb, uint32_t width, uint32_t height)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png != NULL ? png_create_info_struct(png) : NULL;
    int rc = -1;
    if (png != NULL && info != NULL)
    {
        if (setjmp(png_jmpbuf(png)) == 0)
        {
            png_emit(png, info, f, rgb, width, height);
            rc = 0;
        }
    }
    png_destroy_write_struct(&png, &info);
    return rc;
}

int lidet_png_write_rgb(const char *path, const uint8_t *rgb, uint32_t width, uint32_t height)
{
    FILE *f;
    int rc;
    if (width == 0 || height == 0 || width > 0x7FFFFFFFu / 3u)
    {
        return -1;
    }
    f = fopen(path, "wb");
    if (f == NULL)
    {
        return -1;
    }
    rc = png_write_libpng(f, rgb, width, height);
    if (fclose(f) != 0)
    {
        rc = -1;
    }
    return rc;
}

#else /* fallback without libpng: stored (uncompressed) deflate blocks */

static uint32_t crc_table[256];

static void crc_init(void)
{
    uint32_t n, c;
    int k;
    for (n = 0; n < 256; ++n)
    {
        c = n;
        for (k = 0; k < 8; ++k)
        {
            c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        }
        crc_table[n] = c;
    }
}

static uint32_t crc_update(uint32_t crc, const uint8_t *buf, size_t len)
{
    size_t i;
    for (i = 0; i < len; ++i)
    {
        crc = crc_table[(crc ^ buf[i]) & 0xFFu] ^ (crc >> 8);
    }
    return crc;
}

static void put_be32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

static int write_chunk(FILE *f, const char *type, const uint8_t *data, uint32_t len)
{
    uint8_t hdr[8], tail[4];
    uint32_t crc;
    put_be32(hdr, len);
    memcpy(hdr + 4, type, 4);
    crc = crc_update(0xFFFFFFFFu, hdr + 4, 4);
    crc = crc_update(crc, data, len) ^ 0xFFFFFFFFu;
    put_be32(tail, crc);
    return fwrite(hdr, 1, 8, f) == 8 && (len == 0 || fwrite(data, 1, len, f) == len) && fwrite(tail, 1, 4, f) == 4
               ? 0
               : -1;
}

int lidet_png_write_rgb(const char *path, const uint8_t *rgb, uint32_t width, uint32_t height)
{
    static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    const size_t row_bytes = (size_t)width * 3u + 1u;
    const size_t raw_len = row_bytes * height;
    const size_t n_blocks = (raw_len + 65534u) / 65535u;
    const size_t z_len = 2u + raw_len + 5u * n_blocks + 4u;
    uint8_t ihdr[13];
    uint8_t *z, *raw;
    size_t i, pos, off;
    uint32_t a = 1, b = 0, y;
    FILE *f;
    int rc;

    if (width == 0 || height == 0 || z_len > 0x7FFFFFFFu)
    {
        return -1;
    }
    raw = (uint8_t *)malloc(raw_len);
    z = (uint8_t *)malloc(z_len);
    if (raw == NULL || z == NULL)
    {
        free(raw);
        free(z);
        return -1;
    }
    for (y = 0; y < height; ++y)
    {
        raw[y * row_bytes] = 0; /* filter: none */
        memcpy(raw + y * row_bytes + 1, rgb + (size_t)y * width * 3u, (size_t)width * 3u);
    }
    z[0] = 0x78;
    z[1] = 0x01;
    pos = 2;
    for (off = 0; off < raw_len; off += 65535u)
    {
        const size_t len = raw_len - off < 65535u ? raw_len - off : 65535u;
        z[pos++] = (uint8_t)(off + len == raw_len ? 1 : 0);
        z[pos++] = (uint8_t)(len & 0xFFu);
        z[pos++] = (uint8_t)(len >> 8);
        z[pos++] = (uint8_t)(~len & 0xFFu);
        z[pos++] = (uint8_t)((~len >> 8) & 0xFFu);
        memcpy(z + pos, raw + off, len);
        pos += len;
    }
    for (i = 0; i < raw_len; ++i)
    {
        a = (a + raw[i]) % 65521u;
        b = (b + a) % 65521u;
    }
    put_be32(z + pos, (b << 16) | a);
    pos += 4;

    put_be32(ihdr, width);
    put_be32(ihdr + 4, height);
    ihdr[8] = 8;  /* bit depth */
    ihdr[9] = 2;  /* colour type: RGB */
    ihdr[10] = 0; /* deflate */
    ihdr[11] = 0; /* filter method */
    ihdr[12] = 0; /* no interlace */
    crc_init();
    f = fopen(path, "wb");
    rc = -1;
    if (f != NULL)
    {
        rc = (fwrite(sig, 1, 8, f) == 8 && write_chunk(f, "IHDR", ihdr, 13) == 0 &&
              write_chunk(f, "IDAT", z, (uint32_t)pos) == 0 && write_chunk(f, "IEND", NULL, 0) == 0)
                 ? 0
                 : -1;
        if (fclose(f) != 0)
        {
            rc = -1;
        }
    }
    free(raw);
    free(z);
    return rc;
}

#endif /* LIDET_HAVE_LIBPNG */

void cli_colormap(float t, uint8_t rgb[3])
{
    /* piecewise-linear approximation of a perceptual blue -> cyan -> yellow -> red map */
    static const float stops[5][3] = {
        {0.19f, 0.07f, 0.23f}, {0.10f, 0.55f, 0.92f}, {0.25f, 0.92f, 0.55f}, {0.98f, 0.75f, 0.18f}, {0.80f, 0.10f, 0.05f}};
    float s;
    int i, k;
    t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    s = t * 4.0f;
    i = (int)s;
    i = i > 3 ? 3 : i;
    s -= (float)i;
    for (k = 0; k < 3; ++k)
    {
        rgb[k] = (uint8_t)(255.0f * (stops[i][k] + s * (stops[i + 1][k] - stops[i][k])));
    }
}
