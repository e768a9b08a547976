/* png_check.c - reads a PNG written by the viewer (8-bit RGB, unfiltered rows, stored
   deflate blocks: examples/viewer/png.h), checks its structure (signature, every chunk's
   CRC-32, the zlib header, the stored blocks' lengths, the Adler-32), and prints where the
   body is, for tests/test_viewer.sh:

       WIDTH HEIGHT BODY_PIXELS MIN_X MAX_X MIN_Y MAX_Y TIP_TOP TIP_BOTTOM

   Body pixels: those differing from the top-left pixel (the background) by more than 40 in
   a channel, left of 80 % of the width (the legend is on the right). TIP_TOP and TIP_BOTTOM:
   the smallest and largest row of body pixels among the 6 rightmost body columns (rows
   grow downwards). Exit status 0, or 1 with a message for a file it cannot read or check.

       cc -std=c99 -o png_check tests/png_check.c && ./png_check file.png */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static unsigned long crc32_of(const unsigned char *p, size_t n)
{
    unsigned long c = 0xffffffffUL;
    size_t i;
    int k;
    for (i = 0; i < n; i++) {
        c ^= p[i];
        for (k = 0; k < 8; k++) c = (c & 1) ? (c >> 1) ^ 0xedb88320UL : c >> 1;
    }
    return c ^ 0xffffffffUL;
}

static unsigned long be32(const unsigned char *p)
{
    return ((unsigned long)p[0] << 24) | ((unsigned long)p[1] << 16) | ((unsigned long)p[2] << 8) | p[3];
}

static int fail(const char *why)
{
    fprintf(stderr, "png_check: %s\n", why);
    return 1;
}

/* Concatenates the IDAT data of file (n bytes) into *z; reads IHDR. */
static int chunks(const unsigned char *file, size_t n, unsigned long *w, unsigned long *h, unsigned char **z,
                  size_t *zn)
{
    static const unsigned char sig[8] = {137, 'P', 'N', 'G', 13, 10, 26, 10};
    size_t at = 8;
    int seen_end = 0;
    if (n < 8 || memcmp(file, sig, 8) != 0) return fail("no PNG signature");
    *z = (unsigned char *)malloc(n);
    *zn = 0;
    while (at + 12 <= n && !seen_end) {
        unsigned long len = be32(file + at);
        const unsigned char *type = file + at + 4;
        if (len > n - at - 12) return fail("chunk runs past the end");
        if (crc32_of(type, len + 4) != be32(file + at + 8 + len)) return fail("bad chunk CRC");
        if (memcmp(type, "IHDR", 4) == 0) {
            if (len != 13 || type[12] != 8 || type[13] != 2) return fail("not 8-bit RGB");
            *w = be32(type + 4);
            *h = be32(type + 8);
        } else if (memcmp(type, "IDAT", 4) == 0) {
            memcpy(*z + *zn, type + 4, len);
            *zn += len;
        } else if (memcmp(type, "IEND", 4) == 0) seen_end = 1;
        at += 12 + len;
    }
    return seen_end ? 0 : fail("no IEND chunk");
}

/* Stored-block zlib stream to raw bytes (expected: raw_n); checks the Adler-32. */
static int inflate_stored(const unsigned char *z, size_t zn, unsigned char *raw, size_t raw_n)
{
    size_t at = 2, out = 0, i;
    unsigned long a = 1, b = 0;
    int last = 0;
    if (zn < 6 || (z[0] & 0x0f) != 8 || ((z[0] << 8) | z[1]) % 31 != 0) return fail("bad zlib header");
    while (!last) {
        size_t len;
        if (at + 5 > zn) return fail("truncated deflate block");
        if ((z[at] & 6) != 0) return fail("not a stored deflate block");
        last = z[at] & 1;
        len = z[at + 1] | (z[at + 2] << 8);
        if ((len ^ (size_t)(z[at + 3] | (z[at + 4] << 8))) != 0xffff) return fail("bad stored length");
        if (at + 5 + len > zn || out + len > raw_n) return fail("stored block too long");
        memcpy(raw + out, z + at + 5, len);
        out += len;
        at += 5 + len;
    }
    if (out != raw_n || at + 4 > zn) return fail("wrong image data size");
    for (i = 0; i < raw_n; i++) {
        a = (a + raw[i]) % 65521;
        b = (b + a) % 65521;
    }
    return ((b << 16) | a) == be32(z + at) ? 0 : fail("bad Adler-32");
}

static int is_body(const unsigned char *raw, unsigned long w, unsigned long x, unsigned long y)
{
    const unsigned char *bg = raw + 1, *p = raw + y * (3 * w + 1) + 1 + 3 * x;
    int k;
    if (x >= w * 8 / 10) return 0;
    for (k = 0; k < 3; k++)
        if (abs((int)p[k] - (int)bg[k]) > 40) return 1;
    return 0;
}

static void report(const unsigned char *raw, unsigned long w, unsigned long h)
{
    unsigned long x, y, count = 0, x0 = w, x1 = 0, y0 = h, y1 = 0, top = h, bottom = 0;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++)
            if (is_body(raw, w, x, y)) {
                count++;
                if (x < x0) x0 = x;
                if (x > x1) x1 = x;
                if (y < y0) y0 = y;
                if (y > y1) y1 = y;
            }
    for (y = 0; count && y < h; y++)
        for (x = x1 >= 5 ? x1 - 5 : 0; x <= x1; x++)
            if (is_body(raw, w, x, y)) {
                if (y < top) top = y;
                if (y > bottom) bottom = y;
            }
    printf("%lu %lu %lu %lu %lu %lu %lu %lu %lu\n", w, h, count, x0, x1, y0, y1, top, bottom);
}

int main(int argc, char **argv)
{
    FILE *f;
    unsigned char *file, *z = NULL, *raw;
    size_t n, zn = 0;
    unsigned long w = 0, h = 0, y;
    if (argc != 2) return fprintf(stderr, "usage: png_check file.png\n"), 2;
    f = fopen(argv[1], "rb");
    if (!f) return fail("cannot open the file");
    file = (unsigned char *)malloc(64u << 20);
    n = fread(file, 1, 64u << 20, f);
    fclose(f);
    if (chunks(file, n, &w, &h, &z, &zn)) return 1;
    if (w == 0 || h == 0 || w > 8192 || h > 8192) return fail("bad size");
    raw = (unsigned char *)malloc((3 * w + 1) * h);
    if (inflate_stored(z, zn, raw, (3 * w + 1) * h)) return 1;
    for (y = 0; y < h; y++)
        if (raw[y * (3 * w + 1)] != 0) return fail("a row with a filter other than none");
    report(raw, w, h);
    return 0;
}
