/* tetmesh.h - mesh generators, TetGen/Gmsh readers and VTK/OBJ writers for the examples,
   tests and bench of this project. Not part of the model headers (they never include it).

   Do this in exactly one file:
       #define TETMESH_IMPLEMENTATION
       #include "tetmesh.h"
   TETMESH_STATIC makes every function static.

   Coordinates are double whatever precision a model uses; the writers take either float
   or double arrays (TETMESH_TYPE_OF). Tetrahedra are 4 node indices, zero-based,
   positively oriented: (p1 - p0) . ((p2 - p0) x (p3 - p0)) > 0. Every function returns
   TETMESH_OK (0) or a negative TETMESH_ERR_* code and, on failure, leaves its output
   meshes empty and allocates nothing that outlives the call. No global state, no printing.

   READERS take untrusted text. They never size an allocation by a count before checking
   it against the length of the remaining text, and return
     TETMESH_ERR_ARG        a NULL mesh or text;
     TETMESH_ERR_IO         (file readers) a file that cannot be opened or read;
     TETMESH_ERR_PARSE      a missing or non-numeric token, truncated text, a missing
                            section, a non-finite coordinate, an unsupported version
                            (Gmsh other than ASCII 2.2 / 4.1, TetGen dimension other than 3,
                            nodes per tetrahedron other than 4 or 10), TetGen entries not
                            numbered consecutively from 0 or 1, a Gmsh node tag given twice;
     TETMESH_ERR_COUNT      a negative or huge count, a count the rest of the text cannot
                            hold, Gmsh 4.1 block counts that do not add up to the total,
                            no nodes or no tetrahedra at all;
     TETMESH_ERR_RANGE      a tetrahedron naming a node that does not exist, a Gmsh node
                            tag that is not positive;
     TETMESH_ERR_DEGENERATE a tetrahedron of (near) zero volume (see tetmesh_orient).
   Negatively oriented tetrahedra are flipped. Nodes keep their file order, including
   nodes no tetrahedron uses. */
#ifndef TETMESH_H
#define TETMESH_H

#include <stddef.h>

#ifdef TETMESH_STATIC
#define TETMESHDEF static
#else
#define TETMESHDEF extern
#endif

enum {
    TETMESH_OK = 0,
    TETMESH_ERR_ARG = -1,    /* a NULL pointer, a non-positive size or another bad argument */
    TETMESH_ERR_ALLOC = -2,  /* out of memory */
    TETMESH_ERR_IO = -3,     /* the file could not be opened, read or written */
    TETMESH_ERR_PARSE = -4,  /* malformed or truncated text, or an unsupported format version */
    TETMESH_ERR_COUNT = -5,  /* a negative, inconsistent or unreasonably huge count */
    TETMESH_ERR_RANGE = -6,  /* a node index or tag outside the declared range */
    TETMESH_ERR_DEGENERATE = -7 /* a tetrahedron of (near) zero volume */
};

/* A tetrahedral mesh owning its arrays (free with tetmesh_free). */
typedef struct tetmesh {
    int node_count;
    int tet_count;
    double *nodes; /* 3 * node_count coordinates, m */
    int *tets;     /* 4 * tet_count node indices, positively oriented */
} tetmesh;

/* A hexahedral grid owning its arrays (free with hexmesh_free). Hex node order is the
   usual trilinear one: node (a, b, c) of the cell, a, b, c in {0, 1}, is local index
   a + 2 b + 4 c (x fastest). */
typedef struct hexmesh {
    int node_count;
    int hex_count;
    double *nodes; /* 3 * node_count coordinates, m */
    int *hexes;    /* 8 * hex_count node indices */
} hexmesh;

/* How the box generator splits each cube. */
enum { TETMESH_SPLIT5 = 5, TETMESH_SPLIT6 = 6 };

/* Element types for writer arrays. */
enum { TETMESH_DOUBLE = 0, TETMESH_FLOAT = 1 };
#define TETMESH_TYPE_OF(x) (sizeof(x) == sizeof(float) ? TETMESH_FLOAT : TETMESH_DOUBLE)

/* A point-data field for the VTK writer: `components` (1 or 3) values per node. */
typedef struct tetmesh_field {
    const char *name; /* no spaces */
    int components;   /* 1 (scalar) or 3 (vector) */
    int type;         /* TETMESH_DOUBLE or TETMESH_FLOAT */
    const void *data; /* components * node_count values */
} tetmesh_field;

/* Name of an error code. */
TETMESHDEF const char *tetmesh_error_string(int code);

/* ---- generators ---------------------------------------------------------------------- */

/* Box [lo, hi] split in nx * ny * nz cubes (cells), each cut into 5 or 6 tetrahedra
   (split = TETMESH_SPLIT5 or TETMESH_SPLIT6), conforming across cells. Node (i, j, k)
   has index i + (nx + 1) * (j + (ny + 1) * k). */
TETMESHDEF int tetmesh_box(tetmesh *out, const double lo[3], const double hi[3], int nx, int ny,
                           int nz, int split);

/* Beam along +x: [0, length] x [-width/2, width/2] x [-height/2, height/2], clamped face at
   x = 0 by convention (REFERENCES.md), nx * ny * nz cells split as in tetmesh_box. */
TETMESHDEF int tetmesh_beam(tetmesh *out, double length, double width, double height, int nx,
                            int ny, int nz, int split);

/* Cylinder of the given radius along +z from z = 0 to z = length: `rings` rings of cells
   around the axis, `segments` cells around (>= 3), `layers` cells along the axis. A polar
   grid: per layer the axis node then ring 1..rings, segment 0..segments-1 (node
   1 + (ring - 1) * segments + segment), at angle 2 pi segment / segments; the innermost
   ring is cut into one triangular prism per segment, the others into two per cell, and
   each prism into 3 tetrahedra (3 (2 rings - 1) segments layers in all). The cross-section
   is the inscribed regular polygon, so the volume is
   segments / 2 sin(2 pi / segments) radius^2 length, which tends to pi radius^2 length as
   O(segments^-2). */
TETMESHDEF int tetmesh_cylinder(tetmesh *out, double radius, double length, int rings,
                                int segments, int layers);

/* Ellipsoid (x/a)^2 + (y/b)^2 + (z/c)^2 <= 1 around the origin, radii = (a, b, c), carved
   from a box mesh with `cells` cubic cells along its longest axis (5 tets each): the tets
   whose centroid lies inside are kept, then the largest set of them connected through
   faces (no piece hangs by an edge or a vertex), and the unused nodes dropped. The surface
   is stair-stepped, like a voxel segmentation of an organ; the volume converges as
   1/cells. */
TETMESHDEF int tetmesh_ellipsoid(tetmesh *out, const double radii[3], int cells);

/* Hexahedral grid of the box [lo, hi], nx * ny * nz cells; node numbering as tetmesh_box. */
TETMESHDEF int hexmesh_grid(hexmesh *out, const double lo[3], const double hi[3], int nx, int ny,
                            int nz);

/* ---- readers ------------------------------------------------------------------------- */

/* TetGen .node and .ele files: '#' comments, entries numbered consecutively from 0 or 1
   (the first .node entry decides for the node numbers), attributes and boundary markers
   skipped, 4-node tetrahedra; 10-node (second-order) tetrahedra are reduced to their 4
   corners, which TetGen lists first. Text after the last entry is ignored. Allocates
   out's arrays (free with tetmesh_free); errors as listed at the top of this file. */
TETMESHDEF int tetmesh_read_tetgen(tetmesh *out, const char *node_path, const char *ele_path);
/* The same from text in memory (not necessarily NUL-terminated). */
TETMESHDEF int tetmesh_parse_tetgen(tetmesh *out, const char *node_text, size_t node_len,
                                    const char *ele_text, size_t ele_len);

/* Gmsh .msh ASCII, format 2.2 or 4.1 ($MeshFormat first, $Nodes before $Elements, other
   sections skipped; binary files and other versions are refused): nodes and 4-node
   tetrahedra (type 4); other elements are skipped, one line each. Node tags, which may be
   any distinct positive integers, are mapped to zero-based indices in file order. Reading
   stops at $EndElements. Allocates out's arrays (free with tetmesh_free). */
TETMESHDEF int tetmesh_read_gmsh(tetmesh *out, const char *path);
TETMESHDEF int tetmesh_parse_gmsh(tetmesh *out, const char *text, size_t len);

/* ---- writers ------------------------------------------------------------------------- */

/* Legacy VTK unstructured grid (ASCII, "# vtk DataFile Version 3.0") of the tetrahedra
   (cell type 10) with point-data fields (SCALARS or VECTORS, of their own type).
   points: 3 * node_count values of points_type. tets may be NULL with tet_count 0 to write
   a point cloud (one VTK_VERTEX cell, type 1, per node). Values are printed with enough
   digits to read back exactly (%.17g for double, %.9g for float), non-finite ones as the
   C library prints them. Refuses bad arguments (TETMESH_ERR_ARG) and out-of-range
   indices (TETMESH_ERR_RANGE) before creating the file; a failed write removes it
   (TETMESH_ERR_IO). */
TETMESHDEF int tetmesh_write_vtk(const char *path, const void *points, int points_type,
                                 int node_count, const int *tets, int tet_count,
                                 const tetmesh_field *fields, int field_count);

/* Wavefront OBJ of a triangle surface (e.g. from tetmesh_boundary or a model's boundary
   list): "v x y z" per node, "f a b c" (1-based) per triangle; tris may be NULL with
   tri_count 0. Errors as tetmesh_write_vtk. */
TETMESHDEF int tetmesh_write_obj(const char *path, const void *points, int points_type,
                                 int node_count, const int *tris, int tri_count);

/* ---- utilities ----------------------------------------------------------------------- */

/* Boundary triangles of a tetrahedral mesh (faces held by one tetrahedron), oriented
   outwards, in a deterministic order. *tris is allocated (free with free()). */
TETMESHDEF int tetmesh_boundary(const int *tets, int tet_count, int node_count, int **tris,
                                int *tri_count);

/* Swaps two nodes of every negatively oriented tetrahedron; *flipped (may be NULL) counts
   them. Refuses (TETMESH_ERR_DEGENERATE) a tetrahedron whose volume is below 1e-12 times
   the cube of its longest edge. */
TETMESHDEF int tetmesh_orient(tetmesh *m, int *flipped);

/* Signed volume of the tetrahedron (a, b, c, d). */
TETMESHDEF double tetmesh_tet_volume(const double *a, const double *b, const double *c,
                                     const double *d);

/* Index of the node nearest to p. */
TETMESHDEF int tetmesh_nearest_node(const tetmesh *m, const double p[3]);

TETMESHDEF void tetmesh_free(tetmesh *m);
TETMESHDEF void hexmesh_free(hexmesh *m);

#endif /* TETMESH_H */

#if defined(TETMESH_IMPLEMENTATION) && !defined(TETMESH_IMPLEMENTATION_ONCE)
#define TETMESH_IMPLEMENTATION_ONCE

/* With TETMESH_STATIC the functions a program does not call are unused statics. */
#if defined(TETMESH_STATIC) && defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

TETMESHDEF const char *tetmesh_error_string(int code)
{
    switch (code) {
    case TETMESH_OK: return "ok";
    case TETMESH_ERR_ARG: return "bad argument";
    case TETMESH_ERR_ALLOC: return "out of memory";
    case TETMESH_ERR_IO: return "file could not be opened, read or written";
    case TETMESH_ERR_PARSE: return "malformed or truncated mesh text";
    case TETMESH_ERR_COUNT: return "negative, inconsistent or huge count";
    case TETMESH_ERR_RANGE: return "node index out of range";
    case TETMESH_ERR_DEGENERATE: return "degenerate tetrahedron";
    default: return "unknown error";
    }
}

/* >>generators */

TETMESHDEF double tetmesh_tet_volume(const double *a, const double *b, const double *c,
                                     const double *d)
{
    double u[3], v[3], w[3];
    int k;
    for (k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
        w[k] = d[k] - a[k];
    }
    return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
            u[2] * (v[0] * w[1] - v[1] * w[0])) /
           6.0;
}

static void tetmesh__orient_one(const double *nodes, int *t)
{
    if (tetmesh_tet_volume(nodes + 3 * t[0], nodes + 3 * t[1], nodes + 3 * t[2],
                           nodes + 3 * t[3]) < 0.0) {
        int s = t[2];
        t[2] = t[3];
        t[3] = s;
    }
}

/* Largest meshes the generators and readers build (indices stay well inside int). */
#define TETMESH__MAX_NODES 100000000LL
#define TETMESH__MAX_TETS 400000000LL

static int tetmesh__is_finite(double x) { return x - x == 0.0; }

/* Validates the box and cell counts shared by tetmesh_box and hexmesh_grid. */
static int tetmesh__grid_check(const double lo[3], const double hi[3], int nx, int ny, int nz)
{
    long long nodes;
    int k;
    if (!lo || !hi || nx < 1 || ny < 1 || nz < 1) return TETMESH_ERR_ARG;
    for (k = 0; k < 3; k++)
        if (!tetmesh__is_finite(lo[k]) || !tetmesh__is_finite(hi[k]) || !(hi[k] > lo[k]))
            return TETMESH_ERR_ARG;
    nodes = ((long long)nx + 1) * ((long long)ny + 1);
    if (nodes > TETMESH__MAX_NODES) return TETMESH_ERR_COUNT;
    nodes *= (long long)nz + 1;
    return nodes > TETMESH__MAX_NODES ? TETMESH_ERR_COUNT : TETMESH_OK;
}

/* Index of grid node (i, j, k). */
static int tetmesh__grid_node(int i, int j, int k, int nx, int ny)
{
    return i + (nx + 1) * (j + (ny + 1) * k);
}

/* Coordinates of the (nx + 1) (ny + 1) (nz + 1) grid nodes of the box [lo, hi]. */
static void tetmesh__grid_nodes(double *nodes, const double lo[3], const double hi[3], int nx,
                                int ny, int nz)
{
    int i, j, k;
    for (k = 0; k <= nz; k++)
        for (j = 0; j <= ny; j++)
            for (i = 0; i <= nx; i++) {
                double *p = nodes + 3 * tetmesh__grid_node(i, j, k, nx, ny);
                p[0] = lo[0] + (hi[0] - lo[0]) * i / nx;
                p[1] = lo[1] + (hi[1] - lo[1]) * j / ny;
                p[2] = lo[2] + (hi[2] - lo[2]) * k / nz;
            }
}

/* Global indices of the 8 corners of cell (i, j, k), local index a + 2b + 4c. */
static void tetmesh__grid_cell(int i, int j, int k, int nx, int ny, int corner[8])
{
    int c;
    for (c = 0; c < 8; c++)
        corner[c] = tetmesh__grid_node(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2), nx, ny);
}

TETMESHDEF int tetmesh_box(tetmesh *out, const double lo[3], const double hi[3], int nx, int ny,
                           int nz, int split)
{
    /* Cell corners by local index a + 2b + 4c. SPLIT6 is the Kuhn split (the six paths
       from corner 0 to corner 7), identical in every cell and hence conforming. SPLIT5
       cuts one centre tetrahedron and four corner ones, mirrored on odd cells so the
       face diagonals of neighbouring cells agree. */
    static const int kuhn[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                   {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
    static const int five_even[5][4] = {
        {1, 0, 3, 5}, {2, 0, 3, 6}, {4, 0, 5, 6}, {7, 3, 5, 6}, {0, 3, 5, 6}};
    static const int five_odd[5][4] = {
        {0, 1, 2, 4}, {3, 1, 2, 7}, {5, 1, 4, 7}, {6, 2, 4, 7}, {1, 2, 4, 7}};
    int i, j, k, n, t = 0, rc;
    long long nn, nt;
    if (!out) return TETMESH_ERR_ARG;
    memset(out, 0, sizeof *out);
    if (split != TETMESH_SPLIT5 && split != TETMESH_SPLIT6) return TETMESH_ERR_ARG;
    rc = tetmesh__grid_check(lo, hi, nx, ny, nz);
    if (rc) return rc;
    nn = ((long long)nx + 1) * (ny + 1) * (nz + 1);
    nt = (long long)nx * ny * nz * split;
    if (nt > TETMESH__MAX_TETS) return TETMESH_ERR_COUNT;
    out->nodes = (double *)malloc((size_t)nn * 3 * sizeof(double));
    out->tets = (int *)malloc((size_t)nt * 4 * sizeof(int));
    if (!out->nodes || !out->tets) {
        tetmesh_free(out);
        return TETMESH_ERR_ALLOC;
    }
    out->node_count = (int)nn;
    out->tet_count = (int)nt;
    tetmesh__grid_nodes(out->nodes, lo, hi, nx, ny, nz);
    for (k = 0; k < nz; k++)
        for (j = 0; j < ny; j++)
            for (i = 0; i < nx; i++) {
                int corner[8];
                const int(*pattern)[4] =
                    split == 6 ? kuhn : (((i + j + k) & 1) ? five_odd : five_even);
                tetmesh__grid_cell(i, j, k, nx, ny, corner);
                for (n = 0; n < split; n++, t++) {
                    int q;
                    for (q = 0; q < 4; q++) out->tets[4 * t + q] = corner[pattern[n][q]];
                    tetmesh__orient_one(out->nodes, out->tets + 4 * t);
                }
            }
    return TETMESH_OK;
}

TETMESHDEF int tetmesh_beam(tetmesh *out, double length, double width, double height, int nx,
                            int ny, int nz, int split)
{
    double lo[3], hi[3];
    lo[0] = 0.0;
    lo[1] = -0.5 * width;
    lo[2] = -0.5 * height;
    hi[0] = length;
    hi[1] = 0.5 * width;
    hi[2] = 0.5 * height;
    return tetmesh_box(out, lo, hi, nx, ny, nz, split);
}

TETMESHDEF int hexmesh_grid(hexmesh *out, const double lo[3], const double hi[3], int nx, int ny,
                            int nz)
{
    int i, j, k, h = 0, rc;
    long long nn, nh;
    if (!out) return TETMESH_ERR_ARG;
    memset(out, 0, sizeof *out);
    rc = tetmesh__grid_check(lo, hi, nx, ny, nz);
    if (rc) return rc;
    nn = ((long long)nx + 1) * (ny + 1) * (nz + 1);
    nh = (long long)nx * ny * nz;
    out->nodes = (double *)malloc((size_t)nn * 3 * sizeof(double));
    out->hexes = (int *)malloc((size_t)nh * 8 * sizeof(int));
    if (!out->nodes || !out->hexes) {
        hexmesh_free(out);
        return TETMESH_ERR_ALLOC;
    }
    out->node_count = (int)nn;
    out->hex_count = (int)nh;
    tetmesh__grid_nodes(out->nodes, lo, hi, nx, ny, nz);
    for (k = 0; k < nz; k++)
        for (j = 0; j < ny; j++)
            for (i = 0; i < nx; i++, h++) tetmesh__grid_cell(i, j, k, nx, ny, out->hexes + 8 * h);
    return TETMESH_OK;
}

static void tetmesh__set_tet(int *tet, int a, int b, int c, int d)
{
    tet[0] = a;
    tet[1] = b;
    tet[2] = c;
    tet[3] = d;
}

/* Splits the prism with bottom (v[0], v[1], v[2]) and top (v[3], v[4], v[5]), v[i + 3]
   above v[i], into three positive tetrahedra written to tets. Each quadrilateral face is
   cut by the diagonal through its smallest node index, so two prisms sharing a face cut
   it alike whatever else they hold (Dompierre, Labbe, Vallet, Camarero 1999, "How to
   subdivide pyramids, prisms and hexahedra into tetrahedra"). */
static void tetmesh__split_prism(const double *nodes, const int v[6], int *tets)
{
    /* Symmetries of the prism taking vertex m to position 0, bottom and top kept paired. */
    static const int turn[6][6] = {{0, 1, 2, 3, 4, 5}, {1, 2, 0, 4, 5, 3}, {2, 0, 1, 5, 3, 4},
                                   {3, 5, 4, 0, 2, 1}, {4, 3, 5, 1, 0, 2}, {5, 4, 3, 2, 1, 0}};
    int p[6], m = 0, i, t;
    for (i = 1; i < 6; i++)
        if (v[i] < v[m]) m = i;
    for (i = 0; i < 6; i++) p[i] = v[turn[m][i]];
    /* p[0] is the smallest: faces (0,1,4,3) and (0,2,5,3) are cut through it. The corner
       tetrahedron (0,3,4,5) leaves the pyramid (1,2,5,4; apex 0), whose base is cut by
       the diagonal through its own smallest node. */
    tetmesh__set_tet(tets, p[0], p[3], p[4], p[5]);
    if ((p[1] < p[5] ? p[1] : p[5]) < (p[2] < p[4] ? p[2] : p[4])) {
        tetmesh__set_tet(tets + 4, p[0], p[1], p[2], p[5]);
        tetmesh__set_tet(tets + 8, p[0], p[1], p[5], p[4]);
    } else {
        tetmesh__set_tet(tets + 4, p[0], p[1], p[2], p[4]);
        tetmesh__set_tet(tets + 8, p[0], p[4], p[2], p[5]);
    }
    for (t = 0; t < 3; t++) tetmesh__orient_one(nodes, tets + 4 * t);
}

static void tetmesh__set_tri(int *tri, int a, int b, int c)
{
    tri[0] = a;
    tri[1] = b;
    tri[2] = c;
}

/* Index, within a layer of the cylinder, of ring r (0 = the axis node) at segment s. */
static int tetmesh__cylinder_node(int r, int s, int segments)
{
    return r == 0 ? 0 : 1 + (r - 1) * segments + s % segments;
}

/* Nodes of the cylinder: per layer the axis node, then the rings from the inside out. */
static void tetmesh__cylinder_nodes(double *nodes, double radius, double length, int rings,
                                    int segments, int layers)
{
    const double two_pi = 6.28318530717958647692;
    int k, r, s, per_layer = 1 + rings * segments;
    for (k = 0; k <= layers; k++) {
        double *layer = nodes + 3 * (size_t)per_layer * k, z = length * k / layers;
        layer[0] = 0.0;
        layer[1] = 0.0;
        layer[2] = z;
        for (r = 1; r <= rings; r++)
            for (s = 0; s < segments; s++) {
                double *p = layer + 3 * tetmesh__cylinder_node(r, s, segments);
                double angle = two_pi * s / segments, rho = radius * r / rings;
                p[0] = rho * cos(angle);
                p[1] = rho * sin(angle);
                p[2] = z;
            }
    }
}

TETMESHDEF int tetmesh_cylinder(tetmesh *out, double radius, double length, int rings,
                                int segments, int layers)
{
    /* Polar grid: the cross-section is cut into triangles (one per segment around the
       axis, two per quadrilateral cell of the outer rings), each triangle is extruded
       into one prism per layer and every prism split by tetmesh__split_prism. */
    long long per_layer, nn, nt;
    int k, r, s, t = 0;
    if (!out) return TETMESH_ERR_ARG;
    memset(out, 0, sizeof *out);
    if (!tetmesh__is_finite(radius) || !tetmesh__is_finite(length) || !(radius > 0.0) ||
        !(length > 0.0) || rings < 1 || segments < 3 || layers < 1)
        return TETMESH_ERR_ARG;
    per_layer = 1 + (long long)rings * segments;
    if (per_layer > TETMESH__MAX_NODES) return TETMESH_ERR_COUNT;
    nn = per_layer * ((long long)layers + 1);
    nt = 3 * (2 * (long long)rings - 1) * segments * layers;
    if (nn > TETMESH__MAX_NODES || nt > TETMESH__MAX_TETS) return TETMESH_ERR_COUNT;
    out->nodes = (double *)malloc((size_t)nn * 3 * sizeof(double));
    out->tets = (int *)malloc((size_t)nt * 4 * sizeof(int));
    if (!out->nodes || !out->tets) {
        tetmesh_free(out);
        return TETMESH_ERR_ALLOC;
    }
    out->node_count = (int)nn;
    out->tet_count = (int)nt;
    tetmesh__cylinder_nodes(out->nodes, radius, length, rings, segments, layers);
    for (k = 0; k < layers; k++)
        for (s = 0; s < segments; s++)
            for (r = 0; r < rings; r++) {
                /* triangles of the cell between rings r and r + 1, segments s and s + 1 */
                int a = tetmesh__cylinder_node(r, s, segments);
                int b = tetmesh__cylinder_node(r + 1, s, segments);
                int c = tetmesh__cylinder_node(r + 1, s + 1, segments);
                int d = tetmesh__cylinder_node(r, s + 1, segments);
                int tri[2][3], n, q;
                tetmesh__set_tri(tri[0], a, b, c);
                tetmesh__set_tri(tri[1], a, c, d);
                for (n = 0; n < (r == 0 ? 1 : 2); n++, t += 3) {
                    int v[6];
                    for (q = 0; q < 3; q++) {
                        v[q] = (int)(per_layer * k) + tri[n][q];
                        v[q + 3] = v[q] + (int)per_layer;
                    }
                    tetmesh__split_prism(out->nodes, v, out->tets + 4 * t);
                }
            }
    return TETMESH_OK;
}

/* >>utilities */

TETMESHDEF int tetmesh_orient(tetmesh *m, int *flipped)
{
    int t, count = 0;
    if (flipped) *flipped = 0;
    if (!m || (m->tet_count > 0 && (!m->tets || !m->nodes))) return TETMESH_ERR_ARG;
    for (t = 0; t < m->tet_count; t++) {
        int *q = m->tets + 4 * t, a, b;
        double v = tetmesh_tet_volume(m->nodes + 3 * q[0], m->nodes + 3 * q[1],
                                      m->nodes + 3 * q[2], m->nodes + 3 * q[3]);
        double longest = 0.0;
        for (a = 0; a < 4; a++)
            for (b = a + 1; b < 4; b++) {
                const double *pa = m->nodes + 3 * q[a], *pb = m->nodes + 3 * q[b];
                double dx = pa[0] - pb[0], dy = pa[1] - pb[1], dz = pa[2] - pb[2];
                double l = sqrt(dx * dx + dy * dy + dz * dz);
                if (l > longest) longest = l;
            }
        if (!(fabs(v) > 1e-12 * longest * longest * longest)) return TETMESH_ERR_DEGENERATE;
        if (v < 0.0) {
            int s = q[2];
            q[2] = q[3];
            q[3] = s;
            count++;
        }
    }
    if (flipped) *flipped = count;
    return TETMESH_OK;
}

typedef struct tetmesh__face {
    int key[3]; /* sorted node indices */
    int tri[3]; /* outward orientation as seen from the owning tetrahedron */
} tetmesh__face;

static int tetmesh__face_cmp(const void *pa, const void *pb)
{
    const tetmesh__face *a = (const tetmesh__face *)pa, *b = (const tetmesh__face *)pb;
    int k;
    for (k = 0; k < 3; k++)
        if (a->key[k] != b->key[k]) return a->key[k] < b->key[k] ? -1 : 1;
    /* tie-break on orientation so the order is fully deterministic */
    for (k = 0; k < 3; k++)
        if (a->tri[k] != b->tri[k]) return a->tri[k] < b->tri[k] ? -1 : 1;
    return 0;
}

TETMESHDEF int tetmesh_boundary(const int *tets, int tet_count, int node_count, int **tris,
                                int *tri_count)
{
    /* Face opposite local node f of a positive tet (0,1,2,3), wound outwards. */
    static const int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    tetmesh__face *faces;
    int t, f, n = 0, out = 0, i;
    if (tris) *tris = NULL;
    if (tri_count) *tri_count = 0;
    if (!tets || !tris || !tri_count || tet_count < 0 || node_count < 0) return TETMESH_ERR_ARG;
    if (tet_count == 0) return TETMESH_OK;
    faces = (tetmesh__face *)malloc((size_t)tet_count * 4 * sizeof *faces);
    if (!faces) return TETMESH_ERR_ALLOC;
    for (t = 0; t < tet_count; t++)
        for (f = 0; f < 4; f++, n++) {
            int a, b, c, s;
            for (i = 0; i < 3; i++) {
                int v = tets[4 * t + face[f][i]];
                if (v < 0 || v >= node_count) {
                    free(faces);
                    return TETMESH_ERR_RANGE;
                }
                faces[n].tri[i] = v;
            }
            a = faces[n].tri[0];
            b = faces[n].tri[1];
            c = faces[n].tri[2];
            if (a > b) { s = a; a = b; b = s; }
            if (b > c) { s = b; b = c; c = s; }
            if (a > b) { s = a; a = b; b = s; }
            faces[n].key[0] = a;
            faces[n].key[1] = b;
            faces[n].key[2] = c;
        }
    qsort(faces, (size_t)n, sizeof *faces, tetmesh__face_cmp);
    *tris = (int *)malloc((size_t)n * 3 * sizeof(int));
    if (!*tris) {
        free(faces);
        return TETMESH_ERR_ALLOC;
    }
    for (i = 0; i < n;) {
        int j = i + 1;
        while (j < n && faces[j].key[0] == faces[i].key[0] && faces[j].key[1] == faces[i].key[1] &&
               faces[j].key[2] == faces[i].key[2])
            j++;
        if (j - i == 1) {
            memcpy(*tris + 3 * out, faces[i].tri, 3 * sizeof(int));
            out++;
        }
        i = j;
    }
    free(faces);
    *tri_count = out;
    return TETMESH_OK;
}

/* Union-find root with path halving. */
static int tetmesh__root(int *parent, int i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

/* Keeps the largest set of tets connected through shared faces (a tet held by an edge or
   a vertex only would be a mechanism). */
static int tetmesh__keep_largest_component(tetmesh *m)
{
    static const int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    int n = 4 * m->tet_count, i, t, best = -1, best_size = 0, kept = 0, *parent, *size;
    tetmesh__face *faces = (tetmesh__face *)malloc(sizeof *faces * (size_t)n);
    parent = (int *)malloc(sizeof(int) * 2 * (size_t)m->tet_count);
    if (!faces || !parent) {
        free(faces);
        free(parent);
        return TETMESH_ERR_ALLOC;
    }
    size = parent + m->tet_count;
    for (t = 0; t < m->tet_count; t++) {
        int f;
        parent[t] = t;
        size[t] = 0;
        for (f = 0; f < 4; f++) {
            tetmesh__face *fc = faces + 4 * t + f;
            int a = m->tets[4 * t + face[f][0]], b = m->tets[4 * t + face[f][1]],
                c = m->tets[4 * t + face[f][2]], s;
            if (a > b) { s = a; a = b; b = s; }
            if (b > c) { s = b; b = c; c = s; }
            if (a > b) { s = a; a = b; b = s; }
            fc->key[0] = a;
            fc->key[1] = b;
            fc->key[2] = c;
            fc->tri[0] = t; /* the owning tet */
            fc->tri[1] = fc->tri[2] = 0;
        }
    }
    qsort(faces, (size_t)n, sizeof *faces, tetmesh__face_cmp);
    for (i = 0; i + 1 < n; i++)
        if (memcmp(faces[i].key, faces[i + 1].key, sizeof faces[i].key) == 0) {
            int ra = tetmesh__root(parent, faces[i].tri[0]), rb = tetmesh__root(parent, faces[i + 1].tri[0]);
            if (ra != rb) parent[ra] = rb;
        }
    for (t = 0; t < m->tet_count; t++) size[tetmesh__root(parent, t)]++;
    for (t = 0; t < m->tet_count; t++)
        if (size[t] > best_size) {
            best_size = size[t];
            best = t;
        }
    for (t = 0; t < m->tet_count; t++)
        if (tetmesh__root(parent, t) == best) memmove(m->tets + 4 * kept++, m->tets + 4 * t, 4 * sizeof(int));
    m->tet_count = kept;
    free(faces);
    free(parent);
    return TETMESH_OK;
}

TETMESHDEF int tetmesh_ellipsoid(tetmesh *out, const double radii[3], int cells)
{
    tetmesh box;
    double lo[3], hi[3], rmax;
    int n[3], k, t, kept = 0, nodes = 0, err, *map;
    if (!out) return TETMESH_ERR_ARG;
    memset(out, 0, sizeof *out);
    if (!radii || cells < 1) return TETMESH_ERR_ARG;
    for (k = 0; k < 3; k++)
        if (!tetmesh__is_finite(radii[k]) || !(radii[k] > 0.0)) return TETMESH_ERR_ARG;
    rmax = radii[0] > radii[1] ? radii[0] : radii[1];
    rmax = rmax > radii[2] ? rmax : radii[2];
    for (k = 0; k < 3; k++) {
        n[k] = (int)ceil(cells * radii[k] / rmax - 1e-9);
        if (n[k] < 1) n[k] = 1;
        hi[k] = rmax * n[k] / cells; /* cubic cells */
        lo[k] = -hi[k];
    }
    err = tetmesh_box(&box, lo, hi, n[0], n[1], n[2], TETMESH_SPLIT5);
    if (err) return err;
    for (t = 0; t < box.tet_count; t++) {
        double c[3] = {0, 0, 0}, r2 = 0.0;
        int j;
        for (j = 0; j < 4; j++)
            for (k = 0; k < 3; k++) c[k] += 0.25 * box.nodes[3 * box.tets[4 * t + j] + k];
        for (k = 0; k < 3; k++) r2 += (c[k] / radii[k]) * (c[k] / radii[k]);
        if (r2 <= 1.0) memmove(box.tets + 4 * kept++, box.tets + 4 * t, 4 * sizeof(int));
    }
    box.tet_count = kept;
    err = kept ? tetmesh__keep_largest_component(&box) : TETMESH_ERR_ARG;
    map = err ? NULL : (int *)malloc(sizeof(int) * (size_t)box.node_count);
    if (!err && !map) err = TETMESH_ERR_ALLOC;
    if (err) {
        tetmesh_free(&box);
        return err;
    }
    for (k = 0; k < box.node_count; k++) map[k] = -1;
    for (t = 0; t < 4 * box.tet_count; t++) map[box.tets[t]] = 1;
    for (k = 0; k < box.node_count; k++)
        if (map[k] >= 0) {
            memmove(box.nodes + 3 * nodes, box.nodes + 3 * k, 3 * sizeof(double));
            map[k] = nodes++;
        }
    for (t = 0; t < 4 * box.tet_count; t++) box.tets[t] = map[box.tets[t]];
    free(map);
    box.node_count = nodes;
    *out = box;
    return TETMESH_OK;
}

TETMESHDEF int tetmesh_nearest_node(const tetmesh *m, const double p[3])
{
    int i, best = -1;
    double best_d = 0.0;
    for (i = 0; i < m->node_count; i++) {
        const double *q = m->nodes + 3 * i;
        double d = (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
                   (q[2] - p[2]) * (q[2] - p[2]);
        if (best < 0 || d < best_d) {
            best = i;
            best_d = d;
        }
    }
    return best;
}

TETMESHDEF void tetmesh_free(tetmesh *m)
{
    if (!m) return;
    free(m->nodes);
    free(m->tets);
    memset(m, 0, sizeof *m);
}

TETMESHDEF void hexmesh_free(hexmesh *m)
{
    if (!m) return;
    free(m->nodes);
    free(m->hexes);
    memset(m, 0, sizeof *m);
}

/* >>readers */

/* A bounded tokenizer over text that need not be NUL-terminated: tokens are runs of
   non-space bytes, and numbers are converted from a NUL-terminated copy of one token. */
typedef struct tetmesh__lexer {
    const char *text;
    size_t len, pos;
    int hash_comments; /* TetGen: '#' starts a comment that runs to the end of the line */
} tetmesh__lexer;

/* Longest number token accepted (a %.17g double takes 24 bytes). */
#define TETMESH__TOKEN_MAX 128

static void tetmesh__lexer_init(tetmesh__lexer *lx, const char *text, size_t len, int comments)
{
    lx->text = text;
    lx->len = len;
    lx->pos = 0;
    lx->hash_comments = comments;
}

static int tetmesh__is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

static int tetmesh__is_separator(const tetmesh__lexer *lx, char c)
{
    return tetmesh__is_space(c) || (lx->hash_comments && c == '#');
}

static void tetmesh__skip_space(tetmesh__lexer *lx)
{
    while (lx->pos < lx->len) {
        char c = lx->text[lx->pos];
        if (lx->hash_comments && c == '#')
            while (lx->pos < lx->len && lx->text[lx->pos] != '\n') lx->pos++;
        else if (tetmesh__is_space(c))
            lx->pos++;
        else
            break;
    }
}

/* The next token as (*start, *length); returns 0 at the end of the text. */
static int tetmesh__next_token(tetmesh__lexer *lx, const char **start, size_t *length)
{
    size_t begin;
    tetmesh__skip_space(lx);
    begin = lx->pos;
    while (lx->pos < lx->len && !tetmesh__is_separator(lx, lx->text[lx->pos])) lx->pos++;
    *start = lx->text + begin;
    *length = lx->pos - begin;
    return *length > 0;
}

/* Copies the next token into buf, NUL-terminated; returns its length, 0 at the end of the
   text or for a token too long to be a number. */
static size_t tetmesh__copy_token(tetmesh__lexer *lx, char *buf)
{
    const char *start;
    size_t length;
    if (!tetmesh__next_token(lx, &start, &length) || length >= TETMESH__TOKEN_MAX) return 0;
    memcpy(buf, start, length);
    buf[length] = '\0';
    return length;
}

/* An integer token; values beyond long long saturate (and then fail a count or range
   check). */
static int tetmesh__read_int(tetmesh__lexer *lx, long long *value)
{
    char buf[TETMESH__TOKEN_MAX], *end;
    size_t length = tetmesh__copy_token(lx, buf);
    if (length == 0) return TETMESH_ERR_PARSE;
    *value = strtoll(buf, &end, 10);
    return end == buf + length ? TETMESH_OK : TETMESH_ERR_PARSE;
}

/* A finite real token. */
static int tetmesh__read_real(tetmesh__lexer *lx, double *value)
{
    char buf[TETMESH__TOKEN_MAX], *end;
    size_t length = tetmesh__copy_token(lx, buf);
    if (length == 0) return TETMESH_ERR_PARSE;
    *value = strtod(buf, &end);
    if (end != buf + length || !tetmesh__is_finite(*value)) return TETMESH_ERR_PARSE;
    return TETMESH_OK;
}

static int tetmesh__skip_reals(tetmesh__lexer *lx, long long count)
{
    double ignored;
    long long i;
    int rc = TETMESH_OK;
    for (i = 0; i < count && rc == TETMESH_OK; i++) rc = tetmesh__read_real(lx, &ignored);
    return rc;
}

static int tetmesh__skip_ints(tetmesh__lexer *lx, long long count)
{
    long long i, ignored;
    int rc = TETMESH_OK;
    for (i = 0; i < count && rc == TETMESH_OK; i++) rc = tetmesh__read_int(lx, &ignored);
    return rc;
}

/* Refuses a count that is negative, above limit, or larger than the rest of the text could
   hold when each entry takes at least entry_bytes bytes (its tokens and their separators),
   so that no allocation is ever sized by an untrusted count. */
static int tetmesh__check_count(const tetmesh__lexer *lx, long long count, size_t entry_bytes,
                                long long limit)
{
    size_t remaining = lx->len - lx->pos;
    if (count < 0 || count > limit) return TETMESH_ERR_COUNT;
    if ((unsigned long long)count > remaining / entry_bytes) return TETMESH_ERR_COUNT;
    return TETMESH_OK;
}

/* Skips spaces up to the end of the line, which must hold nothing else. */
static int tetmesh__expect_line_end(tetmesh__lexer *lx)
{
    while (lx->pos < lx->len &&
           (lx->text[lx->pos] == ' ' || lx->text[lx->pos] == '\t' || lx->text[lx->pos] == '\r'))
        lx->pos++;
    return lx->pos >= lx->len || lx->text[lx->pos] == '\n' ? TETMESH_OK : TETMESH_ERR_PARSE;
}

/* Skips past the next newline. */
static int tetmesh__skip_line(tetmesh__lexer *lx)
{
    while (lx->pos < lx->len && lx->text[lx->pos] != '\n') lx->pos++;
    if (lx->pos >= lx->len) return TETMESH_ERR_PARSE;
    lx->pos++;
    return TETMESH_OK;
}

/* Allocates the node array of m for count nodes. */
static int tetmesh__alloc_nodes(tetmesh *m, long long count)
{
    m->nodes = (double *)malloc((size_t)count * 3 * sizeof(double));
    if (!m->nodes) return TETMESH_ERR_ALLOC;
    m->node_count = (int)count;
    return TETMESH_OK;
}

static int tetmesh__read_point(tetmesh__lexer *lx, double *p)
{
    int rc = tetmesh__read_real(lx, p);
    if (rc == TETMESH_OK) rc = tetmesh__read_real(lx, p + 1);
    if (rc == TETMESH_OK) rc = tetmesh__read_real(lx, p + 2);
    return rc;
}

/* Finishes a reader: orients the tetrahedra, or empties the mesh after a failure. */
static int tetmesh__finish_read(tetmesh *m, int rc)
{
    if (rc == TETMESH_OK) rc = tetmesh_orient(m, NULL);
    if (rc != TETMESH_OK) tetmesh_free(m);
    return rc;
}

/* >>readers: TetGen */

/* Entry i of a TetGen list is numbered *first + i, with *first (set by entry 0) 0 or 1. */
static int tetmesh__tetgen_number(tetmesh__lexer *lx, long long i, long long *first)
{
    long long number;
    int rc = tetmesh__read_int(lx, &number);
    if (rc) return rc;
    if (i == 0) {
        if (number != 0 && number != 1) return TETMESH_ERR_PARSE;
        *first = number;
    } else if (number != *first + i) {
        return TETMESH_ERR_PARSE;
    }
    return TETMESH_OK;
}

/* .node: "<points> 3 <attributes> <markers 0|1>", then "<number> x y z [attributes]
   [marker]" per point. */
static int tetmesh__tetgen_nodes(tetmesh__lexer *lx, tetmesh *m, long long *first)
{
    long long count, dim, attributes, markers, i;
    int rc = tetmesh__read_int(lx, &count);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(lx, &dim);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(lx, &attributes);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(lx, &markers);
    if (rc) return rc;
    if (dim != 3 || (markers != 0 && markers != 1)) return TETMESH_ERR_PARSE;
    if (attributes < 0 || (unsigned long long)attributes > lx->len) return TETMESH_ERR_COUNT;
    rc = tetmesh__check_count(lx, count, 2 * (size_t)(4 + attributes + markers),
                              TETMESH__MAX_NODES);
    if (rc) return rc;
    if (count == 0) return TETMESH_ERR_COUNT;
    rc = tetmesh__alloc_nodes(m, count);
    for (i = 0; i < count && rc == TETMESH_OK; i++) {
        rc = tetmesh__tetgen_number(lx, i, first);
        if (rc == TETMESH_OK) rc = tetmesh__read_point(lx, m->nodes + 3 * i);
        if (rc == TETMESH_OK) rc = tetmesh__skip_reals(lx, attributes);
        if (rc == TETMESH_OK) rc = tetmesh__skip_ints(lx, markers);
    }
    return rc;
}

/* .ele: "<tetrahedra> <4|10> <attributes>", then "<number> n0 .. n3 [n4 .. n9]
   [attributes]" per tetrahedron; a 10-node tetrahedron keeps its 4 corners (TetGen lists
   them first). Node numbers start at first_node, as in the .node file. */
static int tetmesh__tetgen_tets(tetmesh__lexer *lx, tetmesh *m, long long first_node)
{
    long long count, per_tet, attributes, first = 0, i, k, node;
    int rc = tetmesh__read_int(lx, &count);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(lx, &per_tet);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(lx, &attributes);
    if (rc) return rc;
    if (per_tet != 4 && per_tet != 10) return TETMESH_ERR_PARSE;
    if (attributes < 0 || (unsigned long long)attributes > lx->len) return TETMESH_ERR_COUNT;
    rc = tetmesh__check_count(lx, count, 2 * (size_t)(1 + per_tet + attributes),
                              TETMESH__MAX_TETS);
    if (rc) return rc;
    if (count == 0) return TETMESH_ERR_COUNT;
    m->tets = (int *)malloc((size_t)count * 4 * sizeof(int));
    if (!m->tets) return TETMESH_ERR_ALLOC;
    m->tet_count = (int)count;
    for (i = 0; i < count && rc == TETMESH_OK; i++) {
        rc = tetmesh__tetgen_number(lx, i, &first);
        for (k = 0; k < per_tet && rc == TETMESH_OK; k++) {
            rc = tetmesh__read_int(lx, &node);
            if (rc == TETMESH_OK && (node < first_node || node - first_node >= m->node_count))
                rc = TETMESH_ERR_RANGE;
            if (rc == TETMESH_OK && k < 4) m->tets[4 * i + k] = (int)(node - first_node);
        }
        if (rc == TETMESH_OK) rc = tetmesh__skip_reals(lx, attributes);
    }
    return rc;
}

TETMESHDEF int tetmesh_parse_tetgen(tetmesh *out, const char *node_text, size_t node_len,
                                    const char *ele_text, size_t ele_len)
{
    tetmesh__lexer lx;
    long long first_node = 0;
    int rc;
    if (!out) return TETMESH_ERR_ARG;
    memset(out, 0, sizeof *out);
    if (!node_text || !ele_text) return TETMESH_ERR_ARG;
    tetmesh__lexer_init(&lx, node_text, node_len, 1);
    rc = tetmesh__tetgen_nodes(&lx, out, &first_node);
    if (rc == TETMESH_OK) {
        tetmesh__lexer_init(&lx, ele_text, ele_len, 1);
        rc = tetmesh__tetgen_tets(&lx, out, first_node);
    }
    return tetmesh__finish_read(out, rc);
}

/* >>readers: Gmsh */

/* A node tag and the zero-based index it maps to. */
typedef struct tetmesh__tag {
    long long tag;
    int index;
} tetmesh__tag;

static int tetmesh__tag_cmp(const void *pa, const void *pb)
{
    const tetmesh__tag *a = (const tetmesh__tag *)pa, *b = (const tetmesh__tag *)pb;
    return a->tag < b->tag ? -1 : a->tag > b->tag;
}

typedef struct tetmesh__gmsh {
    tetmesh__lexer lx;
    int version;          /* 2 (format 2.2) or 4 (format 4.1) */
    tetmesh *mesh;        /* nodes filled by $Nodes */
    tetmesh__tag *tags;   /* node_count tags, sorted by tag once $Nodes is read */
    int *tets;            /* 4 * tet_count node indices, grown while $Elements is read */
    long long tet_count, tet_capacity;
} tetmesh__gmsh;

/* The next token must be exactly word. */
static int tetmesh__expect_word(tetmesh__lexer *lx, const char *word)
{
    const char *start;
    size_t length;
    if (!tetmesh__next_token(lx, &start, &length)) return TETMESH_ERR_PARSE;
    return length == strlen(word) && memcmp(start, word, length) == 0 ? TETMESH_OK
                                                                       : TETMESH_ERR_PARSE;
}

/* "$MeshFormat", "<version> <file-type> <data-size>", "$EndMeshFormat": ASCII (file
   type 0) 2.2 or 4.1 only. */
static int tetmesh__gmsh_format(tetmesh__gmsh *g)
{
    double version;
    long long file_type, data_size;
    int rc = tetmesh__expect_word(&g->lx, "$MeshFormat");
    if (rc == TETMESH_OK) rc = tetmesh__read_real(&g->lx, &version);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &file_type);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &data_size);
    if (rc) return rc;
    if (file_type != 0) return TETMESH_ERR_PARSE;
    if (version == 2.2)
        g->version = 2;
    else if (version == 4.1)
        g->version = 4;
    else
        return TETMESH_ERR_PARSE;
    return tetmesh__expect_word(&g->lx, "$EndMeshFormat");
}

/* Skips a section whose header "$<name>" has been read, up to its "$End<name>". */
static int tetmesh__gmsh_skip_section(tetmesh__lexer *lx, const char *name, size_t name_len)
{
    const char *start;
    size_t length;
    while (tetmesh__next_token(lx, &start, &length))
        if (length == name_len + 4 && memcmp(start, "$End", 4) == 0 &&
            memcmp(start + 4, name, name_len) == 0)
            return TETMESH_OK;
    return TETMESH_ERR_PARSE;
}

static int tetmesh__gmsh_alloc_nodes(tetmesh__gmsh *g, long long count)
{
    int rc;
    if (count == 0) return TETMESH_ERR_COUNT;
    rc = tetmesh__alloc_nodes(g->mesh, count);
    if (rc) return rc;
    g->tags = (tetmesh__tag *)malloc((size_t)count * sizeof *g->tags);
    return g->tags ? TETMESH_OK : TETMESH_ERR_ALLOC;
}

/* Node i's tag, which must be positive. */
static int tetmesh__gmsh_read_tag(tetmesh__gmsh *g, long long i)
{
    int rc = tetmesh__read_int(&g->lx, &g->tags[i].tag);
    if (rc) return rc;
    g->tags[i].index = (int)i;
    return g->tags[i].tag > 0 ? TETMESH_OK : TETMESH_ERR_RANGE;
}

/* 2.2 $Nodes: "<count>", then "<tag> x y z" per node. */
static int tetmesh__gmsh_nodes2(tetmesh__gmsh *g)
{
    long long count, i;
    int rc = tetmesh__read_int(&g->lx, &count);
    if (rc == TETMESH_OK) rc = tetmesh__check_count(&g->lx, count, 8, TETMESH__MAX_NODES);
    if (rc == TETMESH_OK) rc = tetmesh__gmsh_alloc_nodes(g, count);
    for (i = 0; i < count && rc == TETMESH_OK; i++) {
        rc = tetmesh__gmsh_read_tag(g, i);
        if (rc == TETMESH_OK) rc = tetmesh__read_point(&g->lx, g->mesh->nodes + 3 * i);
    }
    return rc;
}

/* One 4.1 node block: "<entity-dim> <entity-tag> <parametric> <count>", count tags,
   then count lines "x y z" followed by entity-dim parametric coordinates when
   parametric is 1. Fills nodes *filled onwards. */
static int tetmesh__gmsh_node_block(tetmesh__gmsh *g, long long *filled)
{
    long long dim, entity, parametric, count, i;
    int rc = tetmesh__read_int(&g->lx, &dim);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &entity);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &parametric);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &count);
    if (rc) return rc;
    if (dim < 0 || dim > 3 || (parametric != 0 && parametric != 1)) return TETMESH_ERR_PARSE;
    if (count < 0 || count > g->mesh->node_count - *filled) return TETMESH_ERR_COUNT;
    for (i = 0; i < count && rc == TETMESH_OK; i++) rc = tetmesh__gmsh_read_tag(g, *filled + i);
    for (i = 0; i < count && rc == TETMESH_OK; i++) {
        rc = tetmesh__read_point(&g->lx, g->mesh->nodes + 3 * (*filled + i));
        if (rc == TETMESH_OK) rc = tetmesh__skip_reals(&g->lx, parametric * dim);
    }
    *filled += count;
    return rc;
}

/* 4.1 $Nodes: "<blocks> <count> <min-tag> <max-tag>", then the blocks. */
static int tetmesh__gmsh_nodes4(tetmesh__gmsh *g)
{
    long long blocks, count, min_tag, max_tag, b, filled = 0;
    int rc = tetmesh__read_int(&g->lx, &blocks);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &count);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &min_tag);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &max_tag);
    if (rc == TETMESH_OK) rc = tetmesh__check_count(&g->lx, blocks, 8, TETMESH__MAX_NODES);
    if (rc == TETMESH_OK) rc = tetmesh__check_count(&g->lx, count, 8, TETMESH__MAX_NODES);
    if (rc == TETMESH_OK) rc = tetmesh__gmsh_alloc_nodes(g, count);
    for (b = 0; b < blocks && rc == TETMESH_OK; b++) rc = tetmesh__gmsh_node_block(g, &filled);
    if (rc == TETMESH_OK && filled != count) rc = TETMESH_ERR_COUNT;
    return rc;
}

/* Sorts the tags for lookup; a tag given twice is refused. */
static int tetmesh__gmsh_sort_tags(tetmesh__gmsh *g)
{
    int i, n = g->mesh->node_count;
    qsort(g->tags, (size_t)n, sizeof *g->tags, tetmesh__tag_cmp);
    for (i = 1; i < n; i++)
        if (g->tags[i].tag == g->tags[i - 1].tag) return TETMESH_ERR_PARSE;
    return TETMESH_OK;
}

/* The zero-based index of the node with the given tag. */
static int tetmesh__gmsh_lookup(const tetmesh__gmsh *g, long long tag, int *index)
{
    int lo = 0, hi = g->mesh->node_count - 1;
    while (lo <= hi) {
        int mid = lo + (hi - lo) / 2;
        if (g->tags[mid].tag == tag) {
            *index = g->tags[mid].index;
            return TETMESH_OK;
        }
        if (g->tags[mid].tag < tag)
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return TETMESH_ERR_RANGE;
}

/* Reads the 4 node tags of a tetrahedron, which must end its line, and appends it. */
static int tetmesh__gmsh_add_tet(tetmesh__gmsh *g)
{
    int k, rc = TETMESH_OK, *tet;
    if (g->tet_count >= TETMESH__MAX_TETS) return TETMESH_ERR_COUNT;
    if (g->tet_count == g->tet_capacity) {
        long long capacity = g->tet_capacity ? 2 * g->tet_capacity : 64;
        int *grown = (int *)realloc(g->tets, (size_t)capacity * 4 * sizeof(int));
        if (!grown) return TETMESH_ERR_ALLOC;
        g->tets = grown;
        g->tet_capacity = capacity;
    }
    tet = g->tets + 4 * g->tet_count;
    for (k = 0; k < 4 && rc == TETMESH_OK; k++) {
        long long tag;
        rc = tetmesh__read_int(&g->lx, &tag);
        if (rc == TETMESH_OK) rc = tetmesh__gmsh_lookup(g, tag, tet + k);
    }
    if (rc == TETMESH_OK) rc = tetmesh__expect_line_end(&g->lx);
    if (rc == TETMESH_OK) g->tet_count++;
    return rc;
}

/* 2.2 $Elements: "<count>", then "<tag> <type> <ntags> <tags...> <nodes...>" per line;
   lines of a type other than 4 are skipped whole. */
static int tetmesh__gmsh_elements2(tetmesh__gmsh *g)
{
    long long count, i, tag, type, tags;
    int rc = tetmesh__read_int(&g->lx, &count);
    if (rc == TETMESH_OK) rc = tetmesh__check_count(&g->lx, count, 6, TETMESH__MAX_TETS * 64);
    for (i = 0; i < count && rc == TETMESH_OK; i++) {
        rc = tetmesh__read_int(&g->lx, &tag);
        if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &type);
        if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &tags);
        if (rc == TETMESH_OK && tags < 0) rc = TETMESH_ERR_COUNT; /* sizes no allocation */
        if (rc == TETMESH_OK && type != 4) rc = tetmesh__skip_line(&g->lx);
        if (rc == TETMESH_OK && type == 4) {
            rc = tetmesh__skip_ints(&g->lx, tags);
            if (rc == TETMESH_OK) rc = tetmesh__gmsh_add_tet(g);
        }
    }
    return rc;
}

/* One 4.1 element block: "<entity-dim> <entity-tag> <type> <count>", then count lines
   "<tag> <nodes...>"; blocks of a type other than 4 are skipped line by line. */
static int tetmesh__gmsh_element_block(tetmesh__gmsh *g, long long *done, long long total)
{
    long long dim, entity, type, count, i, tag;
    int rc = tetmesh__read_int(&g->lx, &dim);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &entity);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &type);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &count);
    if (rc) return rc;
    if (count < 0 || count > total - *done) return TETMESH_ERR_COUNT;
    if (type != 4) rc = tetmesh__skip_line(&g->lx); /* the rest of the block header */
    for (i = 0; i < count && rc == TETMESH_OK; i++) {
        if (type != 4) {
            rc = tetmesh__skip_line(&g->lx);
        } else {
            rc = tetmesh__read_int(&g->lx, &tag);
            if (rc == TETMESH_OK) rc = tetmesh__gmsh_add_tet(g);
        }
    }
    *done += count;
    return rc;
}

/* 4.1 $Elements: "<blocks> <count> <min-tag> <max-tag>", then the blocks. */
static int tetmesh__gmsh_elements4(tetmesh__gmsh *g)
{
    long long blocks, count, min_tag, max_tag, b, done = 0;
    int rc = tetmesh__read_int(&g->lx, &blocks);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &count);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &min_tag);
    if (rc == TETMESH_OK) rc = tetmesh__read_int(&g->lx, &max_tag);
    if (rc == TETMESH_OK) rc = tetmesh__check_count(&g->lx, blocks, 8, TETMESH__MAX_TETS * 64);
    if (rc == TETMESH_OK) rc = tetmesh__check_count(&g->lx, count, 4, TETMESH__MAX_TETS * 64);
    for (b = 0; b < blocks && rc == TETMESH_OK; b++)
        rc = tetmesh__gmsh_element_block(g, &done, count);
    if (rc == TETMESH_OK && done != count) rc = TETMESH_ERR_COUNT;
    return rc;
}

/* Reads sections up to $Elements: $Nodes must come first, others are skipped. */
static int tetmesh__gmsh_sections(tetmesh__gmsh *g)
{
    const char *start;
    size_t length;
    int have_nodes = 0, rc = tetmesh__gmsh_format(g);
    while (rc == TETMESH_OK) {
        if (!tetmesh__next_token(&g->lx, &start, &length) || start[0] != '$')
            return TETMESH_ERR_PARSE; /* a missing section, or stray text between sections */
        if (length == 6 && memcmp(start, "$Nodes", 6) == 0) {
            if (have_nodes) return TETMESH_ERR_PARSE;
            rc = g->version == 2 ? tetmesh__gmsh_nodes2(g) : tetmesh__gmsh_nodes4(g);
            if (rc == TETMESH_OK) rc = tetmesh__expect_word(&g->lx, "$EndNodes");
            if (rc == TETMESH_OK) rc = tetmesh__gmsh_sort_tags(g);
            have_nodes = 1;
        } else if (length == 9 && memcmp(start, "$Elements", 9) == 0) {
            if (!have_nodes) return TETMESH_ERR_PARSE;
            rc = g->version == 2 ? tetmesh__gmsh_elements2(g) : tetmesh__gmsh_elements4(g);
            if (rc == TETMESH_OK) rc = tetmesh__expect_word(&g->lx, "$EndElements");
            return rc;
        } else {
            rc = tetmesh__gmsh_skip_section(&g->lx, start + 1, length - 1);
        }
    }
    return rc;
}

TETMESHDEF int tetmesh_parse_gmsh(tetmesh *out, const char *text, size_t len)
{
    tetmesh__gmsh g;
    int rc;
    if (!out) return TETMESH_ERR_ARG;
    memset(out, 0, sizeof *out);
    if (!text) return TETMESH_ERR_ARG;
    memset(&g, 0, sizeof g);
    tetmesh__lexer_init(&g.lx, text, len, 0);
    g.mesh = out;
    rc = tetmesh__gmsh_sections(&g);
    if (rc == TETMESH_OK && g.tet_count == 0) rc = TETMESH_ERR_COUNT;
    free(g.tags);
    out->tets = g.tets; /* handed over, also on failure so that one free releases it */
    out->tet_count = (int)g.tet_count;
    return tetmesh__finish_read(out, rc);
}

/* >>readers: files */

/* Reads a whole file into *text (free with free()). */
static int tetmesh__read_file(const char *path, char **text, size_t *len)
{
    size_t capacity = 1 << 16, n = 0, got;
    char *buf;
    FILE *f;
    *text = NULL;
    *len = 0;
    if (!path) return TETMESH_ERR_ARG;
    f = fopen(path, "rb");
    if (!f) return TETMESH_ERR_IO;
    buf = (char *)malloc(capacity);
    while (buf && (got = fread(buf + n, 1, capacity - n, f)) > 0) {
        n += got;
        if (n == capacity) {
            char *grown = capacity <= (size_t)-1 / 2 ? (char *)realloc(buf, 2 * capacity) : NULL;
            if (!grown) free(buf);
            buf = grown;
            capacity *= 2;
        }
    }
    if (!buf || ferror(f)) {
        int rc = buf ? TETMESH_ERR_IO : TETMESH_ERR_ALLOC;
        free(buf);
        fclose(f);
        return rc;
    }
    fclose(f);
    *text = buf;
    *len = n;
    return TETMESH_OK;
}

TETMESHDEF int tetmesh_read_tetgen(tetmesh *out, const char *node_path, const char *ele_path)
{
    char *node_text = NULL, *ele_text = NULL;
    size_t node_len = 0, ele_len = 0;
    int rc;
    if (!out) return TETMESH_ERR_ARG;
    memset(out, 0, sizeof *out);
    rc = tetmesh__read_file(node_path, &node_text, &node_len);
    if (rc == TETMESH_OK) rc = tetmesh__read_file(ele_path, &ele_text, &ele_len);
    if (rc == TETMESH_OK) rc = tetmesh_parse_tetgen(out, node_text, node_len, ele_text, ele_len);
    free(node_text);
    free(ele_text);
    return rc;
}

TETMESHDEF int tetmesh_read_gmsh(tetmesh *out, const char *path)
{
    char *text = NULL;
    size_t len = 0;
    int rc;
    if (!out) return TETMESH_ERR_ARG;
    memset(out, 0, sizeof *out);
    rc = tetmesh__read_file(path, &text, &len);
    if (rc == TETMESH_OK) rc = tetmesh_parse_gmsh(out, text, len);
    free(text);
    return rc;
}

/* >>writers */

/* Value i of a float or double array, as double. */
static double tetmesh__value(const void *data, int type, size_t i)
{
    return type == TETMESH_FLOAT ? (double)((const float *)data)[i] : ((const double *)data)[i];
}

/* Enough significant digits for the value to read back bit-identical. */
static const char *tetmesh__format(int type) { return type == TETMESH_FLOAT ? "%.9g" : "%.17g"; }

static const char *tetmesh__type_name(int type) { return type == TETMESH_FLOAT ? "float" : "double"; }

static int tetmesh__valid_type(int type) { return type == TETMESH_DOUBLE || type == TETMESH_FLOAT; }

/* Every index of count cells of per_cell nodes is in [0, node_count). */
static int tetmesh__check_cells(const int *cells, int count, int per_cell, int node_count)
{
    size_t i, n = (size_t)count * per_cell;
    for (i = 0; i < n; i++)
        if (cells[i] < 0 || cells[i] >= node_count) return TETMESH_ERR_RANGE;
    return TETMESH_OK;
}

static int tetmesh__check_fields(const tetmesh_field *fields, int field_count)
{
    int f;
    const char *c;
    if (field_count < 0 || (field_count > 0 && !fields)) return TETMESH_ERR_ARG;
    for (f = 0; f < field_count; f++) {
        const tetmesh_field *field = fields + f;
        if (!field->name || !field->name[0] || !field->data || !tetmesh__valid_type(field->type) ||
            (field->components != 1 && field->components != 3))
            return TETMESH_ERR_ARG;
        for (c = field->name; *c; c++)
            if (tetmesh__is_space(*c)) return TETMESH_ERR_ARG;
    }
    return TETMESH_OK;
}

/* Writes count tuples of `components` values, one tuple per line, after prefix. */
static void tetmesh__write_tuples(FILE *f, const char *prefix, const void *data, int type,
                                  int count, int components)
{
    const char *format = tetmesh__format(type);
    int i, k;
    for (i = 0; i < count; i++) {
        fputs(prefix, f);
        for (k = 0; k < components; k++) {
            if (k) fputc(' ', f);
            fprintf(f, format, tetmesh__value(data, type, (size_t)i * components + k));
        }
        fputc('\n', f);
    }
}

/* Closes a file being written; on any write error reports it and removes the file. */
static int tetmesh__close_written(FILE *f, const char *path)
{
    int failed = ferror(f) != 0;
    if (fclose(f) != 0) failed = 1;
    if (!failed) return TETMESH_OK;
    remove(path);
    return TETMESH_ERR_IO;
}

static void tetmesh__vtk_cells(FILE *f, const int *tets, int tet_count, int node_count)
{
    int i;
    if (tets) {
        fprintf(f, "CELLS %d %lld\n", tet_count, 5LL * tet_count);
        for (i = 0; i < tet_count; i++)
            fprintf(f, "4 %d %d %d %d\n", tets[4 * i], tets[4 * i + 1], tets[4 * i + 2],
                    tets[4 * i + 3]);
        fprintf(f, "CELL_TYPES %d\n", tet_count);
        for (i = 0; i < tet_count; i++) fputs("10\n", f);
    } else {
        fprintf(f, "CELLS %d %lld\n", node_count, 2LL * node_count);
        for (i = 0; i < node_count; i++) fprintf(f, "1 %d\n", i);
        fprintf(f, "CELL_TYPES %d\n", node_count);
        for (i = 0; i < node_count; i++) fputs("1\n", f);
    }
}

static void tetmesh__vtk_fields(FILE *f, const tetmesh_field *fields, int field_count,
                                int node_count)
{
    int i;
    if (field_count > 0) fprintf(f, "POINT_DATA %d\n", node_count);
    for (i = 0; i < field_count; i++) {
        const tetmesh_field *field = fields + i;
        if (field->components == 1)
            fprintf(f, "SCALARS %s %s 1\nLOOKUP_TABLE default\n", field->name,
                    tetmesh__type_name(field->type));
        else
            fprintf(f, "VECTORS %s %s\n", field->name, tetmesh__type_name(field->type));
        tetmesh__write_tuples(f, "", field->data, field->type, node_count, field->components);
    }
}

TETMESHDEF int tetmesh_write_vtk(const char *path, const void *points, int points_type,
                                 int node_count, const int *tets, int tet_count,
                                 const tetmesh_field *fields, int field_count)
{
    FILE *f;
    int rc;
    if (!path || !points || !tetmesh__valid_type(points_type) || node_count < 1 ||
        tet_count < 0 || (!tets && tet_count != 0))
        return TETMESH_ERR_ARG;
    rc = tetmesh__check_fields(fields, field_count);
    if (rc == TETMESH_OK && tets) rc = tetmesh__check_cells(tets, tet_count, 4, node_count);
    if (rc) return rc;
    f = fopen(path, "w");
    if (!f) return TETMESH_ERR_IO;
    fputs("# vtk DataFile Version 3.0\ntetmesh.h\nASCII\nDATASET UNSTRUCTURED_GRID\n", f);
    fprintf(f, "POINTS %d %s\n", node_count, tetmesh__type_name(points_type));
    tetmesh__write_tuples(f, "", points, points_type, node_count, 3);
    tetmesh__vtk_cells(f, tets, tet_count, node_count);
    tetmesh__vtk_fields(f, fields, field_count, node_count);
    return tetmesh__close_written(f, path);
}

TETMESHDEF int tetmesh_write_obj(const char *path, const void *points, int points_type,
                                 int node_count, const int *tris, int tri_count)
{
    FILE *f;
    int i, rc;
    if (!path || !points || !tetmesh__valid_type(points_type) || node_count < 1 ||
        tri_count < 0 || (!tris && tri_count != 0))
        return TETMESH_ERR_ARG;
    rc = tris ? tetmesh__check_cells(tris, tri_count, 3, node_count) : TETMESH_OK;
    if (rc) return rc;
    f = fopen(path, "w");
    if (!f) return TETMESH_ERR_IO;
    fputs("# tetmesh.h\n", f);
    tetmesh__write_tuples(f, "v ", points, points_type, node_count, 3);
    for (i = 0; i < tri_count; i++)
        fprintf(f, "f %d %d %d\n", tris[3 * i] + 1, tris[3 * i + 1] + 1, tris[3 * i + 2] + 1);
    return tetmesh__close_written(f, path);
}


#if defined(TETMESH_STATIC) && defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
#endif /* TETMESH_IMPLEMENTATION */
