/* png.h - a minimal PNG writer: 8-bit RGB, no filtering, zlib stream of stored (not
   compressed) deflate blocks, with its CRC-32 and Adler-32. Files are about 3 bytes per
   pixel; any PNG reader opens them. Include in one file (the functions are static).

       int vw_png_write(const char *path, int width, int height, const unsigned char *rgb);

   rgb: width * height * 3 bytes, top row first. Returns 0, or -1 if the file could not be
   written (or width * height is not positive). */
#ifndef VW_PNG_H
#define VW_PNG_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* CRC-32 (ISO 3309, reflected polynomial 0xedb88320), bit by bit: the file is written once. */
static unsigned long vw_png__crc(unsigned long crc, const unsigned char *p, size_t n)
{
    size_t i;
    int k;
    crc = ~crc & 0xffffffffUL;
    for (i = 0; i < n; i++) {
        crc ^= p[i];
        for (k = 0; k < 8; k++) crc = (crc >> 1) ^ (0xedb88320UL & (0UL - (crc & 1)));
    }
    return ~crc & 0xffffffffUL;
}

static void vw_png__be32(unsigned char *p, unsigned long v)
{
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

/* One chunk: length, type, data, CRC of type and data. */
static int vw_png__chunk(FILE *f, const char *type, const unsigned char *data, size_t n)
{
    unsigned char head[8], tail[4];
    unsigned long crc = vw_png__crc(0, (const unsigned char *)type, 4);
    crc = vw_png__crc(crc, data, n);
    vw_png__be32(head, (unsigned long)n);
    memcpy(head + 4, type, 4);
    vw_png__be32(tail, crc);
    return fwrite(head, 1, 8, f) == 8 && (n == 0 || fwrite(data, 1, n, f) == n) && fwrite(tail, 1, 4, f) == 4;
}

/* The zlib stream of raw (filter byte 0 + row) scanlines in stored blocks of <= 65535 bytes. */
static unsigned char *vw_png__zlib(const unsigned char *raw, size_t n, size_t *size)
{
    size_t blocks = n / 65535 + 1, at = 0, o = 2, i;
    unsigned long a = 1, b = 0;
    unsigned char *z = (unsigned char *)malloc(n + 5 * blocks + 6);
    if (!z) return NULL;
    z[0] = 0x78; /* deflate, 32 KiB window */
    z[1] = 0x01; /* no dictionary, check bits: 0x7801 % 31 == 0 */
    do {
        size_t len = n - at < 65535 ? n - at : 65535;
        z[o] = at + len == n; /* BFINAL on the last block, BTYPE 00 (stored) */
        z[o + 1] = (unsigned char)len;
        z[o + 2] = (unsigned char)(len >> 8);
        z[o + 3] = (unsigned char)~len;
        z[o + 4] = (unsigned char)(~len >> 8);
        memcpy(z + o + 5, raw + at, len);
        o += 5 + len;
        at += len;
    } while (at < n);
    for (i = 0; i < n; i++) { /* Adler-32 of the uncompressed data */
        a = (a + raw[i]) % 65521;
        b = (b + a) % 65521;
    }
    vw_png__be32(z + o, (b << 16) | a);
    *size = o + 4;
    return z;
}

static int vw_png_write(const char *path, int width, int height, const unsigned char *rgb)
{
    static const unsigned char signature[8] = {137, 'P', 'N', 'G', 13, 10, 26, 10};
    unsigned char ihdr[13] = {0, 0, 0, 0, 0, 0, 0, 0, 8, 2, 0, 0, 0}; /* 8-bit RGB */
    size_t row = 3 * (size_t)width, n = (row + 1) * (size_t)height, zsize = 0;
    unsigned char *raw, *z = NULL;
    FILE *f;
    int y, ok = 0;
    if (width <= 0 || height <= 0) return -1;
    raw = (unsigned char *)malloc(n);
    if (raw) {
        for (y = 0; y < height; y++) {
            raw[y * (row + 1)] = 0; /* filter: none */
            memcpy(raw + y * (row + 1) + 1, rgb + y * row, row);
        }
        z = vw_png__zlib(raw, n, &zsize);
    }
    f = z ? fopen(path, "wb") : NULL;
    if (f) {
        vw_png__be32(ihdr, (unsigned long)width);
        vw_png__be32(ihdr + 4, (unsigned long)height);
        ok = fwrite(signature, 1, 8, f) == 8 && vw_png__chunk(f, "IHDR", ihdr, 13) &&
             vw_png__chunk(f, "IDAT", z, zsize) && vw_png__chunk(f, "IEND", NULL, 0);
        ok = (fclose(f) == 0) && ok;
    }
    free(raw);
    free(z);
    return ok ? 0 : -1;
}

#endif
