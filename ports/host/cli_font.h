/* SPDX-License-Identifier: MIT */
/* A 5 x 7 bitmap font for the host tools' pictures (cli_font.c): printable ASCII (32..126), any other
 * character as '?'. Glyphs sit in 6 x 9 cells (a column of spacing; 7 rows, a descender row, a row of spacing) times a scale. */
#ifndef LIDET_CLI_FONT_H
#define LIDET_CLI_FONT_H

#include <stdint.h>

#define CLI_FONT_W 5
#define CLI_FONT_H 7    /* rows above the baseline */
#define CLI_FONT_ROWS 8 /* with the descender row (g j p q y) */
#define CLI_FONT_ADVANCE 6

/* width in pixels of s drawn at this scale (no trailing spacing column) */
int cli_font_width(const char *s, int scale);
/* draws s with its top-left corner at pixel (x, y) of an RGB image (width x height, 3 bytes per pixel), each
 * font pixel a scale x scale square of colour c; pixels outside the image are skipped. Returns the width drawn. */
int cli_font_draw(uint8_t *rgb, uint32_t width, uint32_t height, int x, int y, const char *s,
                  const uint8_t c[3], int scale);

#endif
