/* svg.h - a small log-log scatter plot writer for the bench (no plotting dependency).

   svg_plot(path, title, x_label, y_label, series, count) draws each series as markers
   joined in the order given, on decade-ticked log axes fitted to the data, with a legend.
   Points that are not positive and finite are skipped. A series flagged `front` is drawn
   as a thick dashed step line (the Pareto front). Returns 0, or -1 if the file cannot be
   written. */
#ifndef BENCH_SVG_H
#define BENCH_SVG_H

#include <math.h>
#include <stdio.h>

typedef struct svg_series {
    const char *name;
    int count;
    const double *x, *y;
    int front; /* 1: the Pareto front (a step line, no markers) */
} svg_series;

static int svg__ok(double v) { return v > 0 && v < HUGE_VAL; }

static const char *svg__colour(int i)
{
    static const char *c[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b",
                              "#e377c2", "#17becf", "#7f7f7f", "#bcbd22", "#393b79", "#637939"};
    return c[i % 12];
}

static int svg_plot(const char *path, const char *title, const char *x_label, const char *y_label,
                    const svg_series *s, int count)
{
    const double W = 900, left = 80, right = 390, top = 40, bottom = 60;
    const double H = 480 > 80 + 18.0 * count ? 480 : 80 + 18.0 * count; /* room for the legend */
    double lo[2] = {HUGE_VAL, HUGE_VAL}, hi[2] = {-HUGE_VAL, -HUGE_VAL}, pw = W - left - right,
           ph = H - top - bottom;
    int i, j, a, d;
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    for (i = 0; i < count; i++)
        for (j = 0; j < s[i].count; j++)
            if (svg__ok(s[i].x[j]) && svg__ok(s[i].y[j])) {
                double v[2];
                v[0] = log10(s[i].x[j]);
                v[1] = log10(s[i].y[j]);
                for (a = 0; a < 2; a++) {
                    if (v[a] < lo[a]) lo[a] = v[a];
                    if (v[a] > hi[a]) hi[a] = v[a];
                }
            }
    for (a = 0; a < 2; a++) {
        if (lo[a] > hi[a]) lo[a] = 0, hi[a] = 1;
        lo[a] = floor(lo[a]);
        hi[a] = ceil(hi[a]);
        if (hi[a] <= lo[a]) hi[a] = lo[a] + 1;
    }
#define SVG_X(v) (left + (log10(v) - lo[0]) / (hi[0] - lo[0]) * pw)
#define SVG_Y(v) (top + ph - (log10(v) - lo[1]) / (hi[1] - lo[1]) * ph)
    fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%g\" height=\"%g\" "
               "font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
            W, H);
    fprintf(f, "<text x=\"%g\" y=\"24\" font-size=\"15\">%s</text>\n", left, title);
    fprintf(f, "<rect x=\"%g\" y=\"%g\" width=\"%g\" height=\"%g\" fill=\"none\" stroke=\"black\"/>\n", left, top, pw,
            ph);
    for (d = (int)lo[0]; d <= (int)hi[0]; d++) {
        double x = left + (d - lo[0]) / (hi[0] - lo[0]) * pw;
        fprintf(f, "<line x1=\"%g\" y1=\"%g\" x2=\"%g\" y2=\"%g\" stroke=\"#ddd\"/>\n", x, top, x, top + ph);
        fprintf(f, "<text x=\"%g\" y=\"%g\" text-anchor=\"middle\">1e%d</text>\n", x, top + ph + 16, d);
    }
    for (d = (int)lo[1]; d <= (int)hi[1]; d++) {
        double y = top + ph - (d - lo[1]) / (hi[1] - lo[1]) * ph;
        fprintf(f, "<line x1=\"%g\" y1=\"%g\" x2=\"%g\" y2=\"%g\" stroke=\"#ddd\"/>\n", left, y, left + pw, y);
        fprintf(f, "<text x=\"%g\" y=\"%g\" text-anchor=\"end\">1e%d</text>\n", left - 6, y + 4, d);
    }
    fprintf(f, "<text x=\"%g\" y=\"%g\" text-anchor=\"middle\">%s</text>\n", left + pw / 2, H - 18, x_label);
    fprintf(f, "<text transform=\"translate(20 %g) rotate(-90)\" text-anchor=\"middle\">%s</text>\n", top + ph / 2,
            y_label);
    for (i = 0; i < count; i++) {
        const char *c = s[i].front ? "black" : svg__colour(i);
        int first = 1;
        fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"%s\"%s points=\"", c,
                s[i].front ? "2.5" : "1.2", s[i].front ? " stroke-dasharray=\"6 4\"" : "");
        for (j = 0; j < s[i].count; j++) {
            if (!svg__ok(s[i].x[j]) || !svg__ok(s[i].y[j])) continue;
            if (s[i].front && !first) /* a step: along x at the previous error, then down */
                fprintf(f, "%.1f,%.1f ", SVG_X(s[i].x[j]), SVG_Y(s[i].y[j - 1]));
            fprintf(f, "%.1f,%.1f ", SVG_X(s[i].x[j]), SVG_Y(s[i].y[j]));
            first = 0;
        }
        fprintf(f, "\"/>\n");
        if (!s[i].front)
            for (j = 0; j < s[i].count; j++)
                if (svg__ok(s[i].x[j]) && svg__ok(s[i].y[j]))
                    fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3.5\" fill=\"%s\"/>\n", SVG_X(s[i].x[j]),
                            SVG_Y(s[i].y[j]), c);
        fprintf(f, "<line x1=\"%g\" y1=\"%g\" x2=\"%g\" y2=\"%g\" stroke=\"%s\" stroke-width=\"2\"%s/>\n",
                W - right + 14, top + 10 + 18 * i, W - right + 34, top + 10 + 18 * i, c,
                s[i].front ? " stroke-dasharray=\"6 4\"" : "");
        fprintf(f, "<text x=\"%g\" y=\"%g\">%s</text>\n", W - right + 40, top + 14 + 18 * i, s[i].name);
    }
#undef SVG_X
#undef SVG_Y
    fprintf(f, "</svg>\n");
    return fclose(f) == 0 ? 0 : -1;
}

#endif
