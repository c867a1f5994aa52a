/* SPDX-License-Identifier: MIT */
/* The frame of the CLI's bird's-eye-view pictures (cli.h, cli_bev_write): the scene a command drew, put in a
 * larger canvas with a title, axes in metres, a scale bar and a legend, written as a PNG. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "cli_font.h"

#define TEXT_SCALE 2
#define LINE_H (CLI_FONT_ROWS * TEXT_SCALE)
#define MARGIN_L 72
#define MARGIN_R 24
#define PAD 8
#define TICK_MAJOR 8
#define TICK_MINOR 4
/* the axes' ticks every tick_step(half) metres, labels every second tick, the scale bar one tick long: 10 / 20 / 10 m
 * for the 40 m views, down to 1 / 2 / 1 m for a room */
static int tick_step(float half_m)
{
    return half_m >= 30.0f ? 10 : (half_m >= 15.0f ? 5 : (half_m >= 6.0f ? 2 : 1));
}

static const uint8_t k_bg[3] = {24, 24, 30};
static const uint8_t k_text[3] = {230, 230, 230};
static const uint8_t k_axis[3] = {160, 160, 170};

typedef struct
{
    uint8_t *rgb;
    uint32_t w, h;
} canvas_t;

static void fill(const canvas_t *cv, int x0, int y0, int w, int h, const uint8_t c[3])
{
    int x, y;
    for (y = y0; y < y0 + h; ++y)
    {
        for (x = x0; x < x0 + w; ++x)
        {
            uint8_t *p;
            if (x < 0 || y < 0 || x >= (int)cv->w || y >= (int)cv->h)
                continue;
            p = cv->rgb + ((size_t)y * cv->w + (size_t)x) * 3u;
            p[0] = c[0];
            p[1] = c[1];
            p[2] = c[2];
        }
    }
}

/* text at scale 2, or 1 where it would not fit in the canvas width from x */
static void text_fit(const canvas_t *cv, int x, int y, const char *s, const uint8_t c[3])
{
    const int scale = cli_font_width(s, TEXT_SCALE) <= (int)cv->w - x - PAD ? TEXT_SCALE : 1;
    cli_font_draw(cv->rgb, cv->w, cv->h, x, scale == TEXT_SCALE ? y : y + CLI_FONT_H / 2, s, c, scale);
}

/* one legend entry (swatch and label; an empty label: a swatch that shares the next entry's label) at (x, y):
 * its width */
static int legend_item(const canvas_t *cv, int x, int y, const cli_legend_t *it, int draw)
{
    const int sw = LINE_H;
    if (draw)
    {
        fill(cv, x, y, sw, sw, k_axis);
        fill(cv, x + 1, y + 1, sw - 2, sw - 2, it->rgb);
        cli_font_draw(cv->rgb, cv->w, cv->h, x + sw + 6, y, it->label, k_text, TEXT_SCALE);
    }
    return it->label[0] == '\0' ? sw : sw + 6 + cli_font_width(it->label, TEXT_SCALE);
}

/* lays the legend out in rows from y (draw 0: only counts them); returns the number of rows */
static int legend_rows(const canvas_t *cv, int y, const cli_legend_t *items, int n_items, int draw)
{
    const int x_end = (int)cv->w - MARGIN_R;
    int i, x = MARGIN_L, rows = n_items > 0 ? 1 : 0;
    for (i = 0; i < n_items; ++i)
    {
        const int w = legend_item(cv, 0, 0, &items[i], 0);
        if (x > MARGIN_L && x + w > x_end)
        {
            x = MARGIN_L;
            ++rows;
            y += LINE_H + PAD;
        }
        legend_item(cv, x, y, &items[i], draw);
        x += w + (items[i].label[0] == '\0' ? 3 : 3 * PAD);
    }
    return rows;
}

static void axes(const canvas_t *cv, int top, uint32_t sw, uint32_t sh, float res_m, int tick_m)
{
    const int left = MARGIN_L, bottom = top + (int)sh, right = left + (int)sw;
    const int half_y_m = (int)((float)sw * 0.5f * res_m), half_x_m = (int)((float)sh * 0.5f * res_m);
    const int label_m = 2 * tick_m;
    int m;
    char buf[16];
    /* frame one pixel outside the scene */
    fill(cv, left - 1, top - 1, (int)sw + 2, 1, k_axis);
    fill(cv, left - 1, bottom, (int)sw + 2, 1, k_axis);
    fill(cv, left - 1, top - 1, 1, (int)sh + 2, k_axis);
    fill(cv, right, top - 1, 1, (int)sh + 2, k_axis);
    /* bottom axis: y (left positive), so +y is at the left end */
    for (m = -(half_y_m / tick_m) * tick_m; m <= half_y_m; m += tick_m)
    {
        const int col = left + (int)((float)sw * 0.5f - (float)m / res_m + 0.5f);
        const int major = m % label_m == 0;
        if (col < left || col > right)
            continue;
        fill(cv, col, bottom + 1, 1, major ? TICK_MAJOR : TICK_MINOR, k_axis);
        if (major)
        {
            snprintf(buf, sizeof buf, "%d", m);
            cli_font_draw(cv->rgb, cv->w, cv->h, col - cli_font_width(buf, TEXT_SCALE) / 2,
                          bottom + TICK_MAJOR + 4, buf, k_text, TEXT_SCALE);
        }
    }
    /* left axis: x (forward) up */
    for (m = -(half_x_m / tick_m) * tick_m; m <= half_x_m; m += tick_m)
    {
        const int row = top + (int)((float)sh * 0.5f - (float)m / res_m + 0.5f);
        const int major = m % label_m == 0;
        if (row < top || row > bottom)
            continue;
        fill(cv, left - 1 - (major ? TICK_MAJOR : TICK_MINOR), row, major ? TICK_MAJOR : TICK_MINOR, 1,
             k_axis);
        if (major)
        {
            snprintf(buf, sizeof buf, "%d", m);
            cli_font_draw(cv->rgb, cv->w, cv->h, left - TICK_MAJOR - 6 - cli_font_width(buf, TEXT_SCALE),
                          row - CLI_FONT_H * TEXT_SCALE / 2, buf, k_text, TEXT_SCALE);
        }
    }
    /* axis names: x above the left labels, y under the bottom labels */
    cli_font_draw(cv->rgb, cv->w, cv->h, PAD, top - LINE_H - PAD, "x [m]", k_text, TEXT_SCALE);
    cli_font_draw(cv->rgb, cv->w, cv->h, left + (int)sw / 2 - cli_font_width("y [m]", TEXT_SCALE) / 2,
                  bottom + TICK_MAJOR + 4 + LINE_H + PAD, "y [m]", k_text, TEXT_SCALE);
}

static void scale_bar(const canvas_t *cv, int y, float res_m, int bar_m)
{
    const int len = (int)((float)bar_m / res_m + 0.5f);
    char buf[64];
    fill(cv, MARGIN_L, y + LINE_H / 2 - 1, len, 3, k_text);
    fill(cv, MARGIN_L, y, 2, LINE_H, k_text);
    fill(cv, MARGIN_L + len - 2, y, 2, LINE_H, k_text);
    snprintf(buf, sizeof buf, "%d m", bar_m);
    cli_font_draw(cv->rgb, cv->w, cv->h, MARGIN_L + len + PAD, y, buf, k_text, TEXT_SCALE);
    text_fit(cv, MARGIN_L + len + 2 * PAD + cli_font_width(buf, TEXT_SCALE) + 3 * PAD, y,
             "x forward (up), y left, sensor at the centre", k_axis);
}

/* s in lines of the canvas width from (x, y), broken at its double spaces (draw 0: only counts them); a part
 * too wide alone is drawn at scale 1. Returns the number of lines. */
static int text_lines(const canvas_t *cv, int x, int y, const char *s, int draw)
{
    char line[256];
    size_t len = 0;
    int lines = 0;
    const char *p = s;
    while (*p != '\0')
    {
        const char *e = strstr(p, "  ");
        const size_t n = e != NULL ? (size_t)(e - p) : strlen(p);
        char part[256];
        snprintf(part, sizeof part, "%s%.*s", len > 0 ? "  " : "", (int)n, p);
        if (len > 0 && ((int)(len + strlen(part)) * CLI_FONT_ADVANCE - 1) * TEXT_SCALE > (int)cv->w - x - PAD)
        {
            if (draw)
                text_fit(cv, x, y + lines * (LINE_H + PAD), line, k_text);
            ++lines;
            len = 0;
            snprintf(part, sizeof part, "%.*s", (int)n, p);
        }
        if (len + strlen(part) < sizeof line)
        {
            memcpy(line + len, part, strlen(part) + 1);
            len += strlen(part);
        }
        p += n;
        while (*p == ' ')
            ++p;
    }
    if (len > 0)
    {
        if (draw)
            text_fit(cv, x, y + lines * (LINE_H + PAD), line, k_text);
        ++lines;
    }
    return lines;
}

int cli_bev_write(const char *path, const uint8_t *scene, uint32_t sw, uint32_t sh, float res_m,
                  const char *title, const char *subtitle, const cli_legend_t *items, int n_items)
{
    const int below = TICK_MAJOR + 4 + LINE_H + PAD + LINE_H + 2 * PAD; /* tick labels, the y axis name */
    const int tick_m = tick_step((float)sw * 0.5f * res_m);
    canvas_t cv;
    int rows, y, rc, n_title, n_sub, top;
    uint32_t r;
    cv.w = MARGIN_L + sw + MARGIN_R;
    cv.h = 1; /* the layout only needs the width */
    cv.rgb = NULL;
    rows = legend_rows(&cv, 0, items, n_items, 0);
    n_title = text_lines(&cv, PAD, 0, title, 0);
    n_sub = text_lines(&cv, PAD, 0, subtitle, 0);
    top = PAD + (n_title + n_sub) * (LINE_H + PAD) + LINE_H + 2 * PAD; /* title lines, the x axis name */
    cv.h = (uint32_t)(top + (int)sh + below + rows * (LINE_H + PAD) + PAD + LINE_H + 2 * PAD);
    cv.rgb = (uint8_t *)malloc((size_t)cv.w * cv.h * 3u);
    if (cv.rgb == NULL)
        return -1;
    fill(&cv, 0, 0, (int)cv.w, (int)cv.h, k_bg);
    for (r = 0; r < sh; ++r)
        memcpy(cv.rgb + (((size_t)top + r) * cv.w + MARGIN_L) * 3u, scene + (size_t)r * sw * 3u,
               (size_t)sw * 3u);
    text_lines(&cv, PAD, PAD, title, 1);
    text_lines(&cv, PAD, PAD + n_title * (LINE_H + PAD), subtitle, 1);
    axes(&cv, top, sw, sh, res_m, tick_m);
    y = top + (int)sh + below;
    legend_rows(&cv, y, items, n_items, 1);
    scale_bar(&cv, y + rows * (LINE_H + PAD) + PAD, res_m, tick_m);
    rc = lidet_png_write_rgb(path, cv.rgb, cv.w, cv.h);
    free(cv.rgb);
    return rc;
}

/* ---- drawing in a scene (sensor frame -> pixels: +x up, +y left, the sensor at the centre) ---------------- */

const uint8_t cli_rgb_obstacle[3] = {120, 120, 120};
const uint8_t cli_rgb_ground[3] = {45, 45, 55};

void cli_scene_put(const cli_scene_t *s, int u, int v, const uint8_t c[3])
{
    if (u >= 0 && v >= 0 && u < (int)s->w && v < (int)s->h)
    {
        uint8_t *p = s->rgb + ((size_t)v * s->w + (size_t)u) * 3u;
        p[0] = c[0];
        p[1] = c[1];
        p[2] = c[2];
    }
}

void cli_scene_line(const cli_scene_t *s, float x0, float y0, float x1, float y1, const uint8_t c[3])
{
    const float u0 = (float)s->w * 0.5f - y0 / s->res_m, v0 = (float)s->h * 0.5f - x0 / s->res_m;
    const float u1 = (float)s->w * 0.5f - y1 / s->res_m, v1 = (float)s->h * 0.5f - x1 / s->res_m;
    const float du = u1 - u0, dv = v1 - v0;
    int steps, i;
    /* a line far outside (or not finite: the comparisons fail) is not drawn */
    if (!(fabsf(du) <= 4.0f * (float)s->w && fabsf(dv) <= 4.0f * (float)s->w))
        return;
    steps = (int)(fabsf(du) > fabsf(dv) ? fabsf(du) : fabsf(dv)) + 1;
    if (steps > 4 * (int)s->w)
        return;
    for (i = 0; i <= steps; ++i)
    {
        const float t = (float)i / (float)steps;
        const int u = (int)floorf(u0 + t * du), v = (int)floorf(v0 + t * dv);
        cli_scene_put(s, u, v, c);
        cli_scene_put(s, u + 1, v, c);
    }
}

void cli_scene_box(const cli_scene_t *s, const lidet_box_t *b, const uint8_t c[3], int heading)
{
    const float cy = cosf(b->yaw_rad), sy = sinf(b->yaw_rad);
    float x[4], y[4];
    int k;
    for (k = 0; k < 4; ++k)
    {
        const float dx = (k == 0 || k == 3 ? 0.5f : -0.5f) * b->l_m, dy = (k < 2 ? 0.5f : -0.5f) * b->w_m;
        x[k] = b->cx_m + cy * dx - sy * dy;
        y[k] = b->cy_m + sy * dx + cy * dy;
    }
    for (k = 0; k < 4; ++k)
        cli_scene_line(s, x[k], y[k], x[(k + 1) % 4], y[(k + 1) % 4], c);
    if (heading) /* a tick from the centre to the front */
        cli_scene_line(s, b->cx_m, b->cy_m, 0.5f * (x[0] + x[3]), 0.5f * (y[0] + y[3]), c);
}

void cli_scene_points(const cli_scene_t *s, const float *pts, uint32_t n, const uint8_t *ground)
{
    uint32_t i;
    for (i = 0; i < n; ++i)
    {
        const float x = pts[4 * i], y = pts[4 * i + 1];
        const float uf = floorf((float)s->w * 0.5f - y / s->res_m);
        const float vf = floorf((float)s->h * 0.5f - x / s->res_m);
        int u, v;
        /* outside the scene (or not finite): nothing to draw, and no float-to-int conversion out of range */
        if (!(uf >= 0.0f && vf >= 0.0f && uf < (float)s->w && vf < (float)s->h))
            continue;
        u = (int)uf;
        v = (int)vf;
        if (ground != NULL && ground[i])
        {
            if (s->rgb[((size_t)v * s->w + (size_t)u) * 3u] == 0)
                cli_scene_put(s, u, v, cli_rgb_ground);
        }
        else
            cli_scene_put(s, u, v, cli_rgb_obstacle);
    }
}

const char *cli_basename(const char *path)
{
    const char *s = strrchr(path, '/');
    return s != NULL ? s + 1 : path;
}
