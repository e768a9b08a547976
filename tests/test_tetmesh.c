/* test_tetmesh.c - tests of examples/tetmesh.h: generators, TetGen/Gmsh readers (including
   malformed input, one expected error code per case), VTK/OBJ writers.

   Each case is listed in the table at the end and run by test_main() (tests/test.h):

       static void test_box_split6(void) { ... CHECK_INT(TETMESH_OK, rc); ... }
       static const test_case cases[] = { TEST(test_box_split6), ... };
       int main(int argc, char **argv) { return TEST_MAIN(argc, argv, cases); }

   `./test_tetmesh gmsh` runs the cases whose name contains "gmsh". Temporary files go
   under $TEST_TMPDIR (else build/), one name per case, removed when the case ends.

   Written in the common subset of C99 and C++ so the same file builds as both. */
#define TETMESH_IMPLEMENTATION
#include "../examples/tetmesh.h"
#include "test.h"

/* >>helpers */

static double mesh_volume(const tetmesh *m, int *non_positive)
{
    double total = 0.0;
    int t;
    *non_positive = 0;
    for (t = 0; t < m->tet_count; t++) {
        const int *q = m->tets + 4 * t;
        double v = tetmesh_tet_volume(m->nodes + 3 * q[0], m->nodes + 3 * q[1],
                                      m->nodes + 3 * q[2], m->nodes + 3 * q[3]);
        if (!(v > 0.0)) (*non_positive)++;
        total += v;
    }
    return total;
}

static void sort3(int *k)
{
    int s;
    if (k[0] > k[1]) { s = k[0]; k[0] = k[1]; k[1] = s; }
    if (k[1] > k[2]) { s = k[1]; k[1] = k[2]; k[2] = s; }
    if (k[0] > k[1]) { s = k[0]; k[0] = k[1]; k[1] = s; }
}

static int cmp_int3(const void *pa, const void *pb)
{
    const int *a = (const int *)pa, *b = (const int *)pb;
    int k;
    for (k = 0; k < 3; k++)
        if (a[k] != b[k]) return a[k] < b[k] ? -1 : 1;
    return 0;
}

static int cmp_int2(const void *pa, const void *pb)
{
    const int *a = (const int *)pa, *b = (const int *)pb;
    if (a[0] != b[0]) return a[0] < b[0] ? -1 : 1;
    if (a[1] != b[1]) return a[1] < b[1] ? -1 : 1;
    return 0;
}

/* Conformity: every face of every tetrahedron is held by one (boundary) or two
   (interior) tetrahedra, never more, and the boundary faces number expected_boundary. */
static void check_conforming(const tetmesh *m, int expected_boundary)
{
    static const int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    int n = 4 * m->tet_count, i, boundary = 0, overfull = 0;
    int *keys = (int *)malloc((size_t)n * 3 * sizeof(int));
    REQUIRE(keys != NULL);
    for (i = 0; i < n; i++) {
        int k;
        for (k = 0; k < 3; k++) keys[3 * i + k] = m->tets[4 * (i / 4) + face[i % 4][k]];
        sort3(keys + 3 * i);
    }
    qsort(keys, (size_t)n, 3 * sizeof(int), cmp_int3);
    for (i = 0; i < n;) {
        int j = i + 1;
        while (j < n && cmp_int3(keys + 3 * i, keys + 3 * j) == 0) j++;
        if (j - i == 1) boundary++;
        if (j - i > 2) overfull++;
        i = j;
    }
    free(keys);
    CHECK_INT(0, overfull);
    CHECK_INT(expected_boundary, boundary);
}

/* The boundary of m (tetmesh_boundary) is a closed, consistently oriented surface of
   sphere topology enclosing the mesh volume: every directed edge occurs once and its
   reverse once, V - E + F = 2, and the outward triangles enclose `volume`. */
static void check_closed_boundary(const tetmesh *m, int expected_tris, double volume)
{
    int *tris = NULL, n = 0, i, missing = 0, repeated = 0, vertices = 0;
    int *edges, *used;
    double enclosed = 0.0;
    CHECK_INT(TETMESH_OK, tetmesh_boundary(m->tets, m->tet_count, m->node_count, &tris, &n));
    REQUIRE(tris != NULL);
    CHECK_INT(expected_tris, n);
    edges = (int *)malloc((size_t)n * 6 * sizeof(int));
    used = (int *)calloc((size_t)m->node_count, sizeof(int));
    if (!edges || !used) {
        free(edges);
        free(used);
        free(tris);
        REQUIRE(0);
    }
    for (i = 0; i < n; i++) {
        int k;
        const double *p0 = m->nodes + 3 * tris[3 * i], *p1 = m->nodes + 3 * tris[3 * i + 1],
                     *p2 = m->nodes + 3 * tris[3 * i + 2];
        double origin[3] = {0.0, 0.0, 0.0};
        enclosed += tetmesh_tet_volume(origin, p0, p1, p2);
        for (k = 0; k < 3; k++) {
            edges[6 * i + 2 * k] = tris[3 * i + k];
            edges[6 * i + 2 * k + 1] = tris[3 * i + (k + 1) % 3];
            if (!used[tris[3 * i + k]]++) vertices++;
        }
    }
    qsort(edges, (size_t)n * 3, 2 * sizeof(int), cmp_int2);
    for (i = 0; i < 3 * n; i++) {
        int reverse[2];
        if (i > 0 && cmp_int2(edges + 2 * i, edges + 2 * (i - 1)) == 0) repeated++;
        reverse[0] = edges[2 * i + 1];
        reverse[1] = edges[2 * i];
        if (!bsearch(reverse, edges, (size_t)n * 3, 2 * sizeof(int), cmp_int2)) missing++;
    }
    CHECK_INT(0, repeated);
    CHECK_INT(0, missing);
    CHECK_INT(2, vertices - 3 * n / 2 + n); /* Euler characteristic of a sphere */
    CHECK_REL(volume, enclosed, 1e-12);
    free(edges);
    free(used);
    free(tris);
}

/* A copy of a string in a buffer of exactly its length (no NUL), so a reader that reads
   past the end is caught by AddressSanitizer. */
static char *exact_copy(const char *text, size_t len)
{
    char *copy = (char *)malloc(len ? len : 1);
    if (copy && len) memcpy(copy, text, len);
    return copy;
}

static int parse_tetgen(tetmesh *m, const char *node, const char *ele)
{
    size_t node_len = strlen(node), ele_len = strlen(ele);
    char *a = exact_copy(node, node_len), *b = exact_copy(ele, ele_len);
    int rc = a && b ? tetmesh_parse_tetgen(m, a, node_len, b, ele_len) : TETMESH_ERR_ALLOC;
    free(a);
    free(b);
    return rc;
}

static int parse_gmsh(tetmesh *m, const char *text)
{
    size_t len = strlen(text);
    char *a = exact_copy(text, len);
    int rc = a ? tetmesh_parse_gmsh(m, a, len) : TETMESH_ERR_ALLOC;
    free(a);
    return rc;
}

static int mesh_is_empty(const tetmesh *m)
{
    return m->nodes == NULL && m->tets == NULL && m->node_count == 0 && m->tet_count == 0;
}

/* Two meshes hold the same nodes (bit for bit) and the same tetrahedra. */
static void check_same_mesh(const tetmesh *expected, const tetmesh *actual)
{
    int i, node_diff = 0, tet_diff = 0;
    CHECK_INT(expected->node_count, actual->node_count);
    CHECK_INT(expected->tet_count, actual->tet_count);
    if (expected->node_count != actual->node_count || expected->tet_count != actual->tet_count)
        return;
    for (i = 0; i < 3 * expected->node_count; i++)
        if (expected->nodes[i] != actual->nodes[i]) node_diff++;
    for (i = 0; i < 4 * expected->tet_count; i++)
        if (expected->tets[i] != actual->tets[i]) tet_diff++;
    CHECK_INT(0, node_diff);
    CHECK_INT(0, tet_diff);
}

/* A growing text buffer for generated input files. */
typedef struct text_buf {
    char *data;
    size_t len, cap;
} text_buf;

static void text_add(text_buf *t, const char *s)
{
    size_t n = strlen(s);
    if (t->len + n + 1 > t->cap) {
        size_t cap = 2 * (t->len + n + 1);
        char *grown = (char *)realloc(t->data, cap);
        if (!grown) {
            fprintf(stderr, "out of memory\n");
            exit(2);
        }
        t->data = grown;
        t->cap = cap;
    }
    memcpy(t->data + t->len, s, n + 1);
    t->len += n;
}

static void text_addf_int(text_buf *t, const char *format, long long v)
{
    char line[64];
    snprintf(line, sizeof line, format, v);
    text_add(t, line);
}

static void text_add_point(text_buf *t, const double *p)
{
    char line[96];
    snprintf(line, sizeof line, " %.17g %.17g %.17g\n", p[0], p[1], p[2]);
    text_add(t, line);
}

static void text_add_tet(text_buf *t, const int *q, int offset)
{
    char line[96];
    snprintf(line, sizeof line, " %d %d %d %d\n", q[0] + offset, q[1] + offset, q[2] + offset,
             q[3] + offset);
    text_add(t, line);
}

/* Path of a temporary file: $TEST_TMPDIR/tetmesh_<name>, else build/tetmesh_<name>. */
static void temp_path(char *path, size_t size, const char *name)
{
    const char *dir = getenv("TEST_TMPDIR");
    snprintf(path, size, "%s/tetmesh_%s", dir && dir[0] ? dir : "build", name);
}

static int write_text_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    size_t n = strlen(text);
    int ok;
    if (!f) return 0;
    ok = fwrite(text, 1, n, f) == n;
    return fclose(f) == 0 && ok;
}

/* Reads a whole text file, NUL-terminated (free with free()); NULL on failure. */
static char *read_text_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    char *text = NULL;
    long size;
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (size = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0) {
        text = (char *)malloc((size_t)size + 1);
        if (text && fread(text, 1, (size_t)size, f) != (size_t)size) {
            free(text);
            text = NULL;
        }
        if (text) text[size] = '\0';
    }
    fclose(f);
    return text;
}

/* The text after the line that starts with `key` (and the rest of that line), or NULL. */
static const char *after_line(const char *text, const char *key)
{
    const char *p = text;
    size_t n = strlen(key);
    while (p && *p) {
        if (strncmp(p, key, n) == 0) {
            const char *end = strchr(p, '\n');
            return end ? end + 1 : p + strlen(p);
        }
        p = strchr(p, '\n');
        if (p) p++;
    }
    return NULL;
}

/* The line that starts with `key`, or NULL. */
static const char *find_line(const char *text, const char *key)
{
    const char *p = text;
    size_t n = strlen(key);
    while (p && *p) {
        if (strncmp(p, key, n) == 0) return p;
        p = strchr(p, '\n');
        if (p) p++;
    }
    return NULL;
}

/* The text n lines further on, or NULL. */
static const char *skip_lines(const char *p, int n)
{
    while (p && n-- > 0) {
        p = strchr(p, '\n');
        if (p) p++;
    }
    return p;
}

static int count_lines_starting(const char *text, const char *key)
{
    const char *p = text;
    size_t n = strlen(key);
    int count = 0;
    while (p && *p) {
        if (strncmp(p, key, n) == 0) count++;
        p = strchr(p, '\n');
        if (p) p++;
    }
    return count;
}

/* >>generators */

static void check_box(int nx, int ny, int nz, int split)
{
    const double lo[3] = {-0.5, 1.0, 2.0}, hi[3] = {1.5, 1.75, 3.25};
    double volume = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    int boundary = 4 * (nx * ny + ny * nz + nz * nx), non_positive;
    tetmesh m;
    CHECK_INT(TETMESH_OK, tetmesh_box(&m, lo, hi, nx, ny, nz, split));
    REQUIRE(m.nodes != NULL && m.tets != NULL);
    CHECK_INT((nx + 1) * (ny + 1) * (nz + 1), m.node_count);
    CHECK_INT(nx * ny * nz * split, m.tet_count);
    CHECK_REL(volume, mesh_volume(&m, &non_positive), 1e-13);
    CHECK_INT(0, non_positive);
    check_conforming(&m, boundary);
    check_closed_boundary(&m, boundary, volume);
    tetmesh_free(&m);
}

static void test_box_split5(void)
{
    check_box(1, 1, 1, TETMESH_SPLIT5);
    check_box(3, 2, 4, TETMESH_SPLIT5);
    check_box(4, 4, 4, TETMESH_SPLIT5);
}

static void test_box_split6(void)
{
    check_box(1, 1, 1, TETMESH_SPLIT6);
    check_box(3, 2, 4, TETMESH_SPLIT6);
    check_box(5, 1, 2, TETMESH_SPLIT6);
}

static void test_box_node_numbering(void)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {3, 2, 1};
    tetmesh m;
    const double *p;
    REQUIRE(tetmesh_box(&m, lo, hi, 3, 2, 1, TETMESH_SPLIT6) == TETMESH_OK);
    p = m.nodes + 3 * (2 + 4 * (1 + 3 * 1)); /* node (2, 1, 1) */
    CHECK_NEAR(2.0, p[0], 1e-15);
    CHECK_NEAR(1.0, p[1], 1e-15);
    CHECK_NEAR(1.0, p[2], 1e-15);
    tetmesh_free(&m);
}

static void test_box_bad_arguments(void)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, flat[3] = {1, 0, 1};
    const double inf[3] = {1, 1, HUGE_VAL};
    tetmesh m;
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_box(NULL, lo, hi, 1, 1, 1, 6));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_box(&m, lo, hi, 0, 1, 1, 6));
    CHECK(mesh_is_empty(&m));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_box(&m, lo, hi, 1, 1, 1, 4));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_box(&m, lo, flat, 1, 1, 1, 6));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_box(&m, lo, inf, 1, 1, 1, 6));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_box(&m, NULL, hi, 1, 1, 1, 6));
    CHECK_INT(TETMESH_ERR_COUNT, tetmesh_box(&m, lo, hi, 2147483647, 2147483647, 2, 6));
    CHECK(mesh_is_empty(&m));
}

static void test_beam_extents(void)
{
    double min[3] = {1e300, 1e300, 1e300}, max[3] = {-1e300, -1e300, -1e300};
    int i, k, non_positive;
    tetmesh m;
    CHECK_INT(TETMESH_OK, tetmesh_beam(&m, 16.0, 0.5, 0.25, 16, 2, 1, TETMESH_SPLIT6));
    REQUIRE(m.nodes != NULL);
    for (i = 0; i < m.node_count; i++)
        for (k = 0; k < 3; k++) {
            double v = m.nodes[3 * i + k];
            if (v < min[k]) min[k] = v;
            if (v > max[k]) max[k] = v;
        }
    CHECK_NEAR(0.0, min[0], 0.0);
    CHECK_NEAR(16.0, max[0], 1e-12);
    CHECK_NEAR(-0.25, min[1], 0.0);
    CHECK_NEAR(0.25, max[1], 0.0);
    CHECK_NEAR(-0.125, min[2], 0.0);
    CHECK_NEAR(0.125, max[2], 0.0);
    CHECK_REL(16.0 * 0.5 * 0.25, mesh_volume(&m, &non_positive), 1e-13);
    CHECK_INT(0, non_positive);
    tetmesh_free(&m);
}

static double polygon_cylinder_volume(double radius, double length, int segments)
{
    const double two_pi = 6.28318530717958647692;
    return 0.5 * segments * sin(two_pi / segments) * radius * radius * length;
}

static void check_cylinder(double radius, double length, int rings, int segments, int layers)
{
    int non_positive, end_tris = segments * (2 * rings - 1);
    int boundary = 2 * end_tris + 2 * segments * layers;
    double volume = polygon_cylinder_volume(radius, length, segments);
    tetmesh m;
    CHECK_INT(TETMESH_OK, tetmesh_cylinder(&m, radius, length, rings, segments, layers));
    REQUIRE(m.nodes != NULL && m.tets != NULL);
    CHECK_INT((1 + rings * segments) * (layers + 1), m.node_count);
    CHECK_INT(3 * end_tris * layers, m.tet_count);
    CHECK_REL(volume, mesh_volume(&m, &non_positive), 1e-12);
    CHECK_INT(0, non_positive);
    check_conforming(&m, boundary);
    check_closed_boundary(&m, boundary, volume);
    tetmesh_free(&m);
}

static void test_cylinder_conforming_positive(void)
{
    check_cylinder(1.0, 2.0, 1, 3, 1);
    check_cylinder(0.5, 3.0, 2, 7, 3);
    check_cylinder(2.0, 1.0, 4, 16, 5);
}

static void test_cylinder_volume_convergence(void)
{
    /* The error against pi r^2 L falls as segments^-2: halving the spacing divides it by
       about 4 (2 pi^2 / (3 segments^2) relative). */
    const double pi = 3.14159265358979323846, radius = 0.3, length = 2.0;
    double exact = pi * radius * radius * length, previous = 0.0;
    int segments, non_positive, rings, max_segments = TEST_IS_QUICK ? 64 : 128;
    for (segments = 8; segments <= max_segments; segments *= 2) {
        tetmesh m;
        double error;
        rings = segments / 4;
        REQUIRE(tetmesh_cylinder(&m, radius, length, rings, segments, 2) == TETMESH_OK);
        error = exact - mesh_volume(&m, &non_positive);
        CHECK_INT(0, non_positive);
        CHECK(error > 0.0);
        CHECK_REL(2.0 * pi * pi / (3.0 * segments * segments), error / exact, 0.05);
        if (previous > 0.0) CHECK_NEAR(4.0, previous / error, 0.12);
        previous = error;
        tetmesh_free(&m);
    }
}

/* The carved ellipsoid: positive tets, every node used, volume converging to 4/3 pi abc
   (the stair-stepped surface errs by O(1 / cells)), and bad arguments refused. */
static void test_ellipsoid(void)
{
    const double pi = 3.14159265358979323846, radii[3] = {0.15, 0.1, 0.06};
    double exact = 4.0 / 3.0 * pi * radii[0] * radii[1] * radii[2], previous = 1.0, bad[3] = {1, 0, 1};
    int cells, non_positive, i;
    tetmesh m;
    for (cells = 8; cells <= (TEST_IS_QUICK ? 16 : 32); cells *= 2) {
        double error;
        int *used, unused = 0;
        REQUIRE(tetmesh_ellipsoid(&m, radii, cells) == TETMESH_OK);
        error = fabs(mesh_volume(&m, &non_positive) - exact) / exact;
        CHECK_INT(0, non_positive);
        used = (int *)calloc((size_t)m.node_count, sizeof(int));
        for (i = 0; i < 4 * m.tet_count; i++) used[m.tets[i]] = 1;
        for (i = 0; i < m.node_count; i++) unused += !used[i];
        CHECK_INT(0, unused);
        for (i = 0; i < m.node_count; i++) /* nodes within a cell of the surface */
            CHECK(pow(m.nodes[3 * i] / radii[0], 2) + pow(m.nodes[3 * i + 1] / radii[1], 2) +
                      pow(m.nodes[3 * i + 2] / radii[2], 2) < pow(1.0 + 3.0 / cells * 0.15 / 0.06, 2));
        printf("    %d cells: %d tets, volume error %.2f %%\n", cells, m.tet_count, 100 * error);
        CHECK(error < previous);
        CHECK(error < 0.6 / cells);
        previous = error;
        free(used);
        tetmesh_free(&m);
    }
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_ellipsoid(&m, bad, 8));
    CHECK(mesh_is_empty(&m));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_ellipsoid(&m, radii, 0));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_ellipsoid(NULL, radii, 8));
}

static void test_cylinder_bad_arguments(void)
{
    tetmesh m;
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_cylinder(NULL, 1, 1, 1, 3, 1));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_cylinder(&m, 1, 1, 1, 2, 1));
    CHECK(mesh_is_empty(&m));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_cylinder(&m, 0, 1, 1, 3, 1));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_cylinder(&m, 1, -1, 1, 3, 1));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_cylinder(&m, 1, 1, 0, 3, 1));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_cylinder(&m, 1, 1, 1, 3, 0));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_cylinder(&m, HUGE_VAL, 1, 1, 3, 1));
    CHECK_INT(TETMESH_ERR_COUNT, tetmesh_cylinder(&m, 1, 1, 100000, 100000, 1));
    CHECK(mesh_is_empty(&m));
}

/* Determinant of the trilinear map's Jacobian at corner (a, b, c) of hex h. */
static double hex_corner_jacobian(const hexmesh *g, int h, int a, int b, int c)
{
    const int *q = g->hexes + 8 * h;
    double e[3][3];
    int k;
    for (k = 0; k < 3; k++) {
        e[0][k] = g->nodes[3 * q[1 + 2 * b + 4 * c] + k] - g->nodes[3 * q[2 * b + 4 * c] + k];
        e[1][k] = g->nodes[3 * q[a + 2 + 4 * c] + k] - g->nodes[3 * q[a + 4 * c] + k];
        e[2][k] = g->nodes[3 * q[a + 2 * b + 4] + k] - g->nodes[3 * q[a + 2 * b] + k];
    }
    return e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
           e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
           e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
}

static void test_hexmesh_grid(void)
{
    const double lo[3] = {1.0, -1.0, 0.0}, hi[3] = {3.0, 0.5, 0.25};
    const int nx = 4, ny = 3, nz = 2;
    double d[3], volume = 0.0;
    int h, c, i, j, k, bad_order = 0, bad_jacobian = 0;
    hexmesh g;
    CHECK_INT(TETMESH_OK, hexmesh_grid(&g, lo, hi, nx, ny, nz));
    REQUIRE(g.nodes != NULL && g.hexes != NULL);
    CHECK_INT((nx + 1) * (ny + 1) * (nz + 1), g.node_count);
    CHECK_INT(nx * ny * nz, g.hex_count);
    for (k = 0; k < 3; k++) d[k] = (hi[k] - lo[k]) / (k == 0 ? nx : k == 1 ? ny : nz);
    for (h = 0, k = 0; k < nz; k++)
        for (j = 0; j < ny; j++)
            for (i = 0; i < nx; i++, h++) {
                for (c = 0; c < 8; c++) {
                    const double *p = g.nodes + 3 * g.hexes[8 * h + c];
                    if (fabs(p[0] - (lo[0] + d[0] * (i + (c & 1)))) > 1e-12 ||
                        fabs(p[1] - (lo[1] + d[1] * (j + ((c >> 1) & 1)))) > 1e-12 ||
                        fabs(p[2] - (lo[2] + d[2] * (k + (c >> 2)))) > 1e-12)
                        bad_order++;
                    if (!(hex_corner_jacobian(&g, h, c & 1, (c >> 1) & 1, c >> 2) > 0.0))
                        bad_jacobian++;
                }
                /* a parallelepiped: volume = Jacobian determinant */
                volume += hex_corner_jacobian(&g, h, 0, 0, 0);
            }
    CHECK_INT(0, bad_order);
    CHECK_INT(0, bad_jacobian);
    CHECK_REL((hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]), volume, 1e-13);
    /* the same node numbering as tetmesh_box */
    CHECK_INT(1 + (nx + 1) * (2 + (ny + 1) * 1), g.hexes[8 * (1 + nx * (2 + ny * 1))]);
    hexmesh_free(&g);
    CHECK(g.nodes == NULL && g.hexes == NULL && g.hex_count == 0);
    CHECK_INT(TETMESH_ERR_ARG, hexmesh_grid(&g, lo, hi, 1, 0, 1));
    CHECK(g.nodes == NULL && g.hexes == NULL);
    CHECK_INT(TETMESH_ERR_ARG, hexmesh_grid(NULL, lo, hi, 1, 1, 1));
}

/* >>readers: TetGen */

/* TetGen text of m: 1-based when one_based, with comments, 2 node attributes, boundary
   markers and one region attribute per tetrahedron. */
static void tetgen_text(const tetmesh *m, int one_based, text_buf *node, text_buf *ele)
{
    int i;
    text_add(node, "# generated by test_tetmesh\n");
    text_addf_int(node, "%lld 3 2 1  # points, dimension, attributes, markers\n",
                  m->node_count);
    for (i = 0; i < m->node_count; i++) {
        text_addf_int(node, "%lld", i + one_based);
        text_add_point(node, m->nodes + 3 * i);
        node->len--; /* continue the line with attributes and marker */
        text_addf_int(node, " 0.5 -2e3 %lld\n", i % 2);
    }
    text_add(node, "# end\n");
    text_addf_int(ele, "%lld 4 1\n", m->tet_count);
    for (i = 0; i < m->tet_count; i++) {
        text_addf_int(ele, "  %lld", i + one_based);
        text_add_tet(ele, m->tets + 4 * i, one_based);
        ele->len--;
        text_add(ele, " 7   # region\n");
    }
}

static void check_tetgen_round_trip(int one_based)
{
    const double lo[3] = {0.1, -0.2, 0.3}, hi[3] = {1.0 / 3.0, 0.7, 2.0};
    text_buf node = {NULL, 0, 0}, ele = {NULL, 0, 0};
    tetmesh box, back;
    int flipped_back;
    REQUIRE(tetmesh_box(&box, lo, hi, 3, 2, 2, TETMESH_SPLIT5) == TETMESH_OK);
    tetgen_text(&box, one_based, &node, &ele);
    CHECK_INT(TETMESH_OK, parse_tetgen(&back, node.data, ele.data));
    check_same_mesh(&box, &back);
    CHECK_INT(TETMESH_OK, tetmesh_orient(&back, &flipped_back));
    CHECK_INT(0, flipped_back);
    tetmesh_free(&back);
    tetmesh_free(&box);
    free(node.data);
    free(ele.data);
}

static void test_tetgen_round_trip_zero_based(void) { check_tetgen_round_trip(0); }

static void test_tetgen_round_trip_one_based(void) { check_tetgen_round_trip(1); }

static void test_tetgen_flips_negative_tet(void)
{
    /* Tet 2 (1-based nodes 2 3 5 4) is negatively oriented in the file. */
    const char *node = "5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n";
    const char *ele = "2 4 0\n1 1 2 3 4\n2 2 3 5 4\n";
    int non_positive;
    tetmesh m;
    CHECK_INT(TETMESH_OK, parse_tetgen(&m, node, ele));
    REQUIRE(m.tets != NULL);
    CHECK_INT(5, m.node_count);
    CHECK_INT(2, m.tet_count);
    CHECK_REL(0.5, mesh_volume(&m, &non_positive), 1e-15);
    CHECK_INT(0, non_positive);
    CHECK_INT(0, m.tets[0]);
    CHECK_INT(1, m.tets[4]); /* nodes 1 2 4 3 (zero-based) with the last two swapped */
    CHECK_INT(2, m.tets[5]);
    CHECK_INT(3, m.tets[6]);
    CHECK_INT(4, m.tets[7]);
    tetmesh_free(&m);
}

static void test_tetgen_ten_node_tets(void)
{
    /* One second-order tetrahedron: corners first, then the 6 edge midpoints. */
    const char *node = "10 3 0 0\n0 0 0 0\n1 2 0 0\n2 0 2 0\n3 0 0 2\n4 1 0 0\n"
                       "5 1 1 0\n6 0 1 0\n7 0 0 1\n8 1 0 1\n9 0 1 1\n";
    const char *ele = "#second order\n1 10 0\n0 0 1 2 3 4 5 6 7 8 9\n";
    tetmesh m;
    CHECK_INT(TETMESH_OK, parse_tetgen(&m, node, ele));
    REQUIRE(m.tets != NULL);
    CHECK_INT(1, m.tet_count);
    CHECK_INT(0, m.tets[0]);
    CHECK_INT(1, m.tets[1]);
    CHECK_INT(2, m.tets[2]);
    CHECK_INT(3, m.tets[3]);
    tetmesh_free(&m);
}

static void test_tetgen_not_nul_terminated(void)
{
    /* The lengths end the texts before trailing bytes that would otherwise be read. */
    const char node[] = "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1999";
    const char ele[] = "1 4 0\n0 0 1 2 3999";
    tetmesh m;
    CHECK_INT(TETMESH_OK, tetmesh_parse_tetgen(&m, node, sizeof node - 4, ele, sizeof ele - 4));
    REQUIRE(m.nodes != NULL);
    CHECK_NEAR(1.0, m.nodes[11], 0.0);
    CHECK_INT(3, m.tets[3]);
    tetmesh_free(&m);
}

typedef struct tetgen_case {
    const char *name;
    const char *node;
    const char *ele;
    int expected;
} tetgen_case;

#define TG_NODE "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n"
#define TG_ELE "1 4 0\n0 0 1 2 3\n"

static const tetgen_case tetgen_bad[] = {
    {"empty node text", "", TG_ELE, TETMESH_ERR_PARSE},
    {"empty ele text", TG_NODE, "", TETMESH_ERR_PARSE},
    {"comment only", "# nothing\n", TG_ELE, TETMESH_ERR_PARSE},
    {"truncated node header", "4 3 0", TG_ELE, TETMESH_ERR_PARSE},
    {"truncated node list", "4 3 0 0\n0 0.0 0.0 0.0\n1 1.0 0.0 0.0\n2 0.0 1.0 0.0\n3 0.0 0.0",
     TG_ELE, TETMESH_ERR_PARSE},
    {"truncated ele list", TG_NODE, "2 4 0  # two\n0 0 1 2 3\n1 0 1", TETMESH_ERR_PARSE},
    {"garbage count", "four 3 0 0\n", TG_ELE, TETMESH_ERR_PARSE},
    {"garbage coordinate", "4 3 0 0\n0 0 0 0\n1 1 x 0\n2 0 1 0\n3 0 0 1\n", TG_ELE,
     TETMESH_ERR_PARSE},
    {"trailing garbage on number", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1x\n", TG_ELE,
     TETMESH_ERR_PARSE},
    {"fractional node index", TG_NODE, "1 4 0\n0 0 1.5 2 3\n", TETMESH_ERR_PARSE},
    {"over-long token", TG_NODE,
     "1 4 0\n0 0 1 2 000000000000000000000000000000000000000000000000000000000000000000000"
     "000000000000000000000000000000000000000000000000000000000000000000000003\n",
     TETMESH_ERR_PARSE},
    {"nan coordinate", "4 3 0 0\n0 0 0 0\n1 nan 0 0\n2 0 1 0\n3 0 0 1\n", TG_ELE,
     TETMESH_ERR_PARSE},
    {"inf coordinate", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 -inf 0\n3 0 0 1\n", TG_ELE,
     TETMESH_ERR_PARSE},
    {"overflowing coordinate", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1e999\n", TG_ELE,
     TETMESH_ERR_PARSE},
    {"dimension 2", "4 2 0 0\n0 0 0\n1 1 0\n2 0 1\n3 1 1\n", TG_ELE, TETMESH_ERR_PARSE},
    {"marker flag 2", "4 3 0 2\n0 0 0 0 1\n1 1 0 0 1\n2 0 1 0 1\n3 0 0 1 1\n", TG_ELE,
     TETMESH_ERR_PARSE},
    {"3 nodes per element", TG_NODE, "1 3 0\n0 0 1 2\n", TETMESH_ERR_PARSE},
    {"first index 2", "4 3 0 0\n2 0 0 0\n3 1 0 0\n4 0 1 0\n5 0 0 1\n", TG_ELE,
     TETMESH_ERR_PARSE},
    {"non-consecutive numbers", "4 3 0 0\n0 0 0 0\n1 1 0 0\n3 0 1 0\n2 0 0 1\n", TG_ELE,
     TETMESH_ERR_PARSE},
    {"missing attribute",
     "4 3 1 0\n0 0.0 0.0 0.0 1.5\n1 1.0 0.0 0.0 1.5\n2 0.0 1.0 0.0 1.5\n3 0.0 0.0 1.0\n", TG_ELE,
     TETMESH_ERR_PARSE},
    {"negative node count", "-4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n", TG_ELE,
     TETMESH_ERR_COUNT},
    {"negative tet count", TG_NODE, "-1 4 0\n0 0 1 2 3\n", TETMESH_ERR_COUNT},
    {"negative attribute count", "4 3 -1 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n", TG_ELE,
     TETMESH_ERR_COUNT},
    {"huge node count", "1000000000000 3 0 0\n0 0 0 0\n", TG_ELE, TETMESH_ERR_COUNT},
    {"huge tet count", TG_NODE, "1000000000000 4 0\n0 0 1 2 3\n", TETMESH_ERR_COUNT},
    {"huge attribute count", "4 3 1000000000000 0\n0 0 0 0\n", TG_ELE, TETMESH_ERR_COUNT},
    {"count beyond long long", "99999999999999999999999 3 0 0\n0 0 0 0\n", TG_ELE,
     TETMESH_ERR_COUNT},
    {"node count larger than the text", "400 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n",
     TG_ELE, TETMESH_ERR_COUNT},
    {"tet count larger than the text", TG_NODE, "9 4 0\n0 0 1 2 3\n", TETMESH_ERR_COUNT},
    {"no nodes", "0 3 0 0\n", TG_ELE, TETMESH_ERR_COUNT},
    {"no tets", TG_NODE, "0 4 0\n", TETMESH_ERR_COUNT},
    {"node index past the end", TG_NODE, "1 4 0\n0 0 1 2 4\n", TETMESH_ERR_RANGE},
    {"negative node index", TG_NODE, "1 4 0\n0 0 1 -1 3\n", TETMESH_ERR_RANGE},
    {"huge node index", TG_NODE, "1 4 0\n0 0 1 2 99999999999999999999999\n",
     TETMESH_ERR_RANGE},
    {"zero index in a 1-based file", "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n",
     "1 4 0\n1 0 1 2 3\n", TETMESH_ERR_RANGE},
    {"degenerate tet", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 1 1 0\n", TG_ELE,
     TETMESH_ERR_DEGENERATE},
    {"repeated node in a tet", TG_NODE, "1 4 0\n0 0 1 2 2\n", TETMESH_ERR_DEGENERATE},
};

static void test_tetgen_malformed(void)
{
    size_t i;
    for (i = 0; i < sizeof tetgen_bad / sizeof tetgen_bad[0]; i++) {
        tetmesh m;
        int rc;
        memset(&m, 0xab, sizeof m); /* the reader must not trust or free what is there */
        rc = parse_tetgen(&m, tetgen_bad[i].node, tetgen_bad[i].ele);
        CHECK_INT(tetgen_bad[i].expected, rc);
        CHECK(mesh_is_empty(&m));
        if (rc != tetgen_bad[i].expected || !mesh_is_empty(&m))
            fprintf(stderr, "    in case \"%s\"\n", tetgen_bad[i].name);
        if (rc == TETMESH_OK) tetmesh_free(&m);
    }
}

static void test_tetgen_embedded_nul(void)
{
    const char node[] = "4 3 0 0\n0 0 0 0\n1 1\0 0 0\n2 0 1 0\n3 0 0 1\n";
    tetmesh m;
    CHECK_INT(TETMESH_ERR_PARSE,
              tetmesh_parse_tetgen(&m, node, sizeof node - 1, TG_ELE, strlen(TG_ELE)));
    CHECK(mesh_is_empty(&m));
}

static void test_tetgen_null_arguments(void)
{
    tetmesh m;
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_parse_tetgen(NULL, TG_NODE, 10, TG_ELE, 10));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_parse_tetgen(&m, NULL, 0, TG_ELE, strlen(TG_ELE)));
    CHECK(mesh_is_empty(&m));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_parse_tetgen(&m, TG_NODE, strlen(TG_NODE), NULL, 0));
    CHECK(mesh_is_empty(&m));
}

static void test_tetgen_files(void)
{
    char node_path[512], ele_path[512], missing[512];
    tetmesh m;
    temp_path(node_path, sizeof node_path, "files.node");
    temp_path(ele_path, sizeof ele_path, "files.ele");
    temp_path(missing, sizeof missing, "no_such_file.node");
    REQUIRE(write_text_file(node_path, TG_NODE) && write_text_file(ele_path, TG_ELE));
    CHECK_INT(TETMESH_OK, tetmesh_read_tetgen(&m, node_path, ele_path));
    CHECK_INT(4, m.node_count);
    CHECK_INT(1, m.tet_count);
    tetmesh_free(&m);
    remove(missing);
    CHECK_INT(TETMESH_ERR_IO, tetmesh_read_tetgen(&m, missing, ele_path));
    CHECK(mesh_is_empty(&m));
    CHECK_INT(TETMESH_ERR_IO, tetmesh_read_tetgen(&m, node_path, missing));
    CHECK(mesh_is_empty(&m));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_read_tetgen(&m, NULL, ele_path));
    remove(node_path);
    remove(ele_path);
}

/* >>readers: Gmsh */

/* Unit tetrahedron plus a negatively oriented one sharing its slanted face, node tags
   10..50, with points, lines and triangles to be skipped. */
static const char gmsh22_text[] = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                                  "$PhysicalNames\n1\n3 1 \"the body\"\n$EndPhysicalNames\n"
                                  "$Nodes\n5\n10 0 0 0\n20 1 0 0\n30 0 1 0\n40 0 0 1\n"
                                  "50 1 1 1\n$EndNodes\n"
                                  "$Elements\n5\n1 15 2 0 1 10\n2 1 2 0 1 10 20\n"
                                  "3 2 2 0 1 10 20 30\n4 4 2 1 1 10 20 30 40\n"
                                  "5 4 3 1 1 0 20 30 50 40\n$EndElements\n"
                                  "$NodeData\n1\n\"t\"\n$EndNodeData\n";

/* The same mesh in 4.1: an $Entities section, three node blocks (one parametric) with
   tags 3, 7, 100, 50, 107 out of order, element blocks of points, triangles and tets. */
static const char gmsh41_text[] =
    "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
    "$Entities\n1 0 0 1\n1 0 0 0 0\n1 0 0 0 1 1 1 0 0\n$EndEntities\n"
    "$Nodes\n3 5 3 107\n"
    "0 1 0 1\n3\n0 0 0\n"
    "1 1 1 2\n7\n100\n1 0 0 0.5\n0 1 0 0.25\n"
    "3 1 0 2\n50\n107\n0 0 1\n1 1 1\n"
    "$EndNodes\n"
    "$Elements\n3 4 1 4\n"
    "0 1 15 1\n1 3 \n"
    "2 1 2 1\n2 3 7 100 \n"
    "3 1 4 2\n3 3 7 100 50 \n4 7 100 107 50 \n"
    "$EndElements\n";

static void check_two_tets(const tetmesh *m, const int *expected_tets)
{
    static const double expected_nodes[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
    int i, non_positive, node_diff = 0;
    CHECK_INT(5, m->node_count);
    CHECK_INT(2, m->tet_count);
    if (m->node_count != 5 || m->tet_count != 2) return;
    for (i = 0; i < 15; i++)
        if (m->nodes[i] != expected_nodes[i]) node_diff++;
    CHECK_INT(0, node_diff);
    for (i = 0; i < 8; i++) CHECK_INT(expected_tets[i], m->tets[i]);
    CHECK_REL(0.5, mesh_volume(m, &non_positive), 1e-15);
    CHECK_INT(0, non_positive);
}

static void test_gmsh22_mixed_elements(void)
{
    /* tags 10 20 30 40 50 -> 0..4; tet 2 (20 30 50 40) = (1 2 4 3) is flipped to (1 2 3 4) */
    static const int expected[8] = {0, 1, 2, 3, 1, 2, 3, 4};
    tetmesh m;
    CHECK_INT(TETMESH_OK, parse_gmsh(&m, gmsh22_text));
    check_two_tets(&m, expected);
    tetmesh_free(&m);
}

static void test_gmsh41_blocks_and_tags(void)
{
    /* tags in file order 3 7 100 50 107 -> 0..4; tet 2 (7 100 107 50) = (1 2 4 3) is
       flipped to (1 2 3 4) */
    static const int expected[8] = {0, 1, 2, 3, 1, 2, 3, 4};
    tetmesh m;
    CHECK_INT(TETMESH_OK, parse_gmsh(&m, gmsh41_text));
    check_two_tets(&m, expected);
    tetmesh_free(&m);
}

/* Gmsh text of m with node tags 1000 + 7 i (and a triangle per tet to skip). */
static void gmsh_text(const tetmesh *m, int version, text_buf *t)
{
    int i, half = m->node_count / 2;
    text_add(t, version == 2 ? "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                             : "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
    if (version == 2) {
        text_addf_int(t, "$Nodes\n%lld\n", m->node_count);
        for (i = 0; i < m->node_count; i++) {
            text_addf_int(t, "%lld", 1000 + 7 * i);
            text_add_point(t, m->nodes + 3 * i);
        }
        text_addf_int(t, "$EndNodes\n$Elements\n%lld\n", 2LL * m->tet_count);
        for (i = 0; i < m->tet_count; i++) {
            const int *q = m->tets + 4 * i;
            char line[128];
            snprintf(line, sizeof line, "%d 2 0 %d %d %d\n%d 4 2 1 1 %d %d %d %d\n", 2 * i + 1,
                     1000 + 7 * q[0], 1000 + 7 * q[1], 1000 + 7 * q[2], 2 * i + 2,
                     1000 + 7 * q[0], 1000 + 7 * q[1], 1000 + 7 * q[2], 1000 + 7 * q[3]);
            text_add(t, line);
        }
    } else {
        int b;
        text_addf_int(t, "$Nodes\n2 %lld 1000 ", m->node_count);
        text_addf_int(t, "%lld\n", 1000 + 7 * (m->node_count - 1));
        for (b = 0; b < 2; b++) {
            int from = b ? half : 0, to = b ? m->node_count : half;
            text_addf_int(t, "3 1 0 %lld\n", to - from);
            for (i = from; i < to; i++) text_addf_int(t, "%lld\n", 1000 + 7 * i);
            for (i = from; i < to; i++) text_add_point(t, m->nodes + 3 * i);
        }
        text_addf_int(t, "$EndNodes\n$Elements\n2 %lld 1 ", 2LL * m->tet_count);
        text_addf_int(t, "%lld\n", 2LL * m->tet_count);
        text_addf_int(t, "2 1 2 %lld\n", m->tet_count);
        for (i = 0; i < m->tet_count; i++) {
            const int *q = m->tets + 4 * i;
            char line[96];
            snprintf(line, sizeof line, "%d %d %d %d\n", i + 1, 1000 + 7 * q[0],
                     1000 + 7 * q[1], 1000 + 7 * q[2]);
            text_add(t, line);
        }
        text_addf_int(t, "3 1 4 %lld\n", m->tet_count);
        for (i = 0; i < m->tet_count; i++) {
            const int *q = m->tets + 4 * i;
            char line[96];
            snprintf(line, sizeof line, "%d %d %d %d %d\n", m->tet_count + i + 1,
                     1000 + 7 * q[0], 1000 + 7 * q[1], 1000 + 7 * q[2], 1000 + 7 * q[3]);
            text_add(t, line);
        }
    }
    text_add(t, "$EndElements\n");
}

static void check_gmsh_round_trip(int version)
{
    text_buf text = {NULL, 0, 0};
    tetmesh cylinder, back;
    REQUIRE(tetmesh_cylinder(&cylinder, 0.25, 1.5, 2, 9, 3) == TETMESH_OK);
    gmsh_text(&cylinder, version, &text);
    CHECK_INT(TETMESH_OK, parse_gmsh(&back, text.data));
    check_same_mesh(&cylinder, &back);
    tetmesh_free(&back);
    tetmesh_free(&cylinder);
    free(text.data);
}

static void test_gmsh22_round_trip(void) { check_gmsh_round_trip(2); }

static void test_gmsh41_round_trip(void) { check_gmsh_round_trip(4); }

static void test_gmsh_crlf_and_no_final_newline(void)
{
    const char *text = "$MeshFormat\r\n2.2 0 8\r\n$EndMeshFormat\r\n$Nodes\r\n4\r\n1 0 0 0\r\n"
                       "2 1 0 0\r\n3 0 1 0\r\n4 0 0 1\r\n$EndNodes\r\n$Elements\r\n1\r\n"
                       "1 4 0 1 2 3 4\r\n$EndElements";
    tetmesh m;
    CHECK_INT(TETMESH_OK, parse_gmsh(&m, text));
    CHECK_INT(1, m.tet_count);
    tetmesh_free(&m);
}

typedef struct gmsh_case {
    const char *name;
    const char *text;
    int expected;
} gmsh_case;

#define G22_HEAD "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
#define G22_NODES "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n"
#define G22_ELEMS "$Elements\n1\n1 4 2 0 1 1 2 3 4\n$EndElements\n"
#define G41_HEAD "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
#define G41_NODES "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n"
#define G41_ELEMS "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n"

static const gmsh_case gmsh_bad[] = {
    {"empty", "", TETMESH_ERR_PARSE},
    {"no $MeshFormat", G22_NODES G22_ELEMS, TETMESH_ERR_PARSE},
    {"version 3.0", "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n" G22_NODES G22_ELEMS,
     TETMESH_ERR_PARSE},
    {"version 4.0", "$MeshFormat\n4 0 8\n$EndMeshFormat\n" G41_NODES G41_ELEMS,
     TETMESH_ERR_PARSE},
    {"binary 2.2", "$MeshFormat\n2.2 1 8\n\x01\0\0\0\n$EndMeshFormat\n" G22_NODES G22_ELEMS,
     TETMESH_ERR_PARSE},
    {"binary 4.1", "$MeshFormat\n4.1 1 8\n$EndMeshFormat\n" G41_NODES G41_ELEMS,
     TETMESH_ERR_PARSE},
    {"garbage version", "$MeshFormat\nv2 0 8\n$EndMeshFormat\n" G22_NODES G22_ELEMS,
     TETMESH_ERR_PARSE},
    {"unterminated $MeshFormat", "$MeshFormat\n2.2 0 8\n" G22_NODES G22_ELEMS,
     TETMESH_ERR_PARSE},
    {"missing $Nodes", G22_HEAD G22_ELEMS, TETMESH_ERR_PARSE},
    {"missing $Elements", G22_HEAD G22_NODES, TETMESH_ERR_PARSE},
    {"$Nodes twice", G22_HEAD G22_NODES G22_NODES G22_ELEMS, TETMESH_ERR_PARSE},
    {"stray text between sections", G22_HEAD G22_NODES "junk\n" G22_ELEMS, TETMESH_ERR_PARSE},
    {"unterminated unknown section", G22_HEAD "$Comments\nhello\n", TETMESH_ERR_PARSE},
    {"more nodes than counted", G22_HEAD "$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"
                                         "$EndNodes\n" G22_ELEMS,
     TETMESH_ERR_PARSE},
    {"truncated in $Nodes",
     G22_HEAD "$Nodes\n4\n1 0.0 0.0 0.0\n2 1.0 0.0 0.0\n3 0.0 1.0 0.0\n4 0.0 0.0",
     TETMESH_ERR_PARSE},
    {"truncated in $Elements", G22_HEAD G22_NODES "$Elements\n2\n1 4 2 0 1 1 2 3 4\n2 4 2 0",
     TETMESH_ERR_PARSE},
    {"truncated in a skipped element", G22_HEAD G22_NODES "$Elements\n2\n1 4 2 0 1 1 2 3 4\n"
                                                          "2 2 2 0 1 1 2",
     TETMESH_ERR_PARSE},
    {"garbage coordinate", G22_HEAD "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 one 0\n4 0 0 1\n"
                                    "$EndNodes\n" G22_ELEMS,
     TETMESH_ERR_PARSE},
    {"garbage element tag", G22_HEAD G22_NODES "$Elements\n1\n1 4 2 0 1 1 2 x 4\n$EndElements\n",
     TETMESH_ERR_PARSE},
    {"nan coordinate", G22_HEAD "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 NaN\n"
                                "$EndNodes\n" G22_ELEMS,
     TETMESH_ERR_PARSE},
    {"inf coordinate", G41_HEAD "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 inf 0\n"
                                "0 0 1\n$EndNodes\n" G41_ELEMS,
     TETMESH_ERR_PARSE},
    {"duplicate node tag", G22_HEAD "$Nodes\n4\n1 0 0 0\n2 1 0 0\n2 0 1 0\n4 0 0 1\n"
                                    "$EndNodes\n" G22_ELEMS,
     TETMESH_ERR_PARSE},
    {"tet with 5 nodes", G22_HEAD G22_NODES "$Elements\n1\n1 4 2 0 1 1 2 3 4 4\n$EndElements\n",
     TETMESH_ERR_PARSE},
    {"tet line with a token that would pass for the next element",
     G22_HEAD G22_NODES "$Elements\n2\n1 4 0 1 2 3 4 2\n4 0 1 2 3 4\n$EndElements\n",
     TETMESH_ERR_PARSE},
    {"$Elements before $Nodes", G22_HEAD G22_ELEMS G22_NODES, TETMESH_ERR_PARSE},
    {"4.1 parametric flag 2", G41_HEAD "$Nodes\n1 4 1 4\n3 1 2 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n"
                                       "0 1 0\n0 0 1\n$EndNodes\n" G41_ELEMS,
     TETMESH_ERR_PARSE},
    {"4.1 missing parametric coordinate",
     G41_HEAD "$Nodes\n1 4 1 4\n1 1 1 4\n1\n2\n3\n4\n0 0 0 0\n1 0 0 1\n0 1 0\n0 0 1 3\n"
              "$EndNodes\n" G41_ELEMS,
     TETMESH_ERR_PARSE},
    {"negative node count", G22_HEAD "$Nodes\n-4\n1 0 0 0\n$EndNodes\n" G22_ELEMS,
     TETMESH_ERR_COUNT},
    {"huge node count", G22_HEAD "$Nodes\n1000000000000\n1 0 0 0\n$EndNodes\n" G22_ELEMS,
     TETMESH_ERR_COUNT},
    {"node count larger than the text", G22_HEAD "$Nodes\n40\n1 0 0 0\n2 1 0 0\n3 0 1 0\n"
                                                 "4 0 0 1\n$EndNodes\n" G22_ELEMS,
     TETMESH_ERR_COUNT},
    {"no nodes", G22_HEAD "$Nodes\n0\n$EndNodes\n" G22_ELEMS, TETMESH_ERR_COUNT},
    {"negative element count", G22_HEAD G22_NODES "$Elements\n-1\n1 4 2 0 1 1 2 3 4\n"
                                                  "$EndElements\n",
     TETMESH_ERR_COUNT},
    {"huge element count", G22_HEAD G22_NODES "$Elements\n1000000000000\n1 4 2 0 1 1 2 3 4\n"
                                              "$EndElements\n",
     TETMESH_ERR_COUNT},
    {"negative number of element tags", G22_HEAD G22_NODES "$Elements\n1\n1 4 -2 1 2 3 4\n"
                                                           "$EndElements\n",
     TETMESH_ERR_COUNT},
    {"no tets", G22_HEAD G22_NODES "$Elements\n1\n1 2 2 0 1 1 2 3\n$EndElements\n",
     TETMESH_ERR_COUNT},
    {"4.1 huge block count", G41_HEAD "$Nodes\n1000000000000 4 1 4\n3 1 0 4\n1\n2\n3\n4\n"
                                      "0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n" G41_ELEMS,
     TETMESH_ERR_COUNT},
    {"4.1 node blocks exceed the total", G41_HEAD "$Nodes\n1 3 1 4\n3 1 0 4\n1\n2\n3\n4\n"
                                                  "0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n"
                                                  G41_ELEMS,
     TETMESH_ERR_COUNT},
    {"4.1 node blocks short of the total", G41_HEAD "$Nodes\n2 5 1 5\n3 1 0 4\n1\n2\n3\n4\n"
                                                    "0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n"
                                                    G41_ELEMS,
     TETMESH_ERR_PARSE},
    {"4.1 negative block size", G41_HEAD "$Nodes\n1 4 1 4\n3 1 0 -4\n$EndNodes\n" G41_ELEMS,
     TETMESH_ERR_COUNT},
    {"4.1 element blocks short of the total", G41_HEAD G41_NODES
     "$Elements\n1 2 1 2\n3 1 4 1\n1 1 2 3 4\n$EndElements\n",
     TETMESH_ERR_COUNT},
    {"4.1 huge element block", G41_HEAD G41_NODES
     "$Elements\n1 1 1 1\n3 1 4 1000000000000\n1 1 2 3 4\n$EndElements\n",
     TETMESH_ERR_COUNT},
    {"element node tag unknown (2.2)", G22_HEAD G22_NODES
     "$Elements\n1\n1 4 2 0 1 1 2 3 5\n$EndElements\n",
     TETMESH_ERR_RANGE},
    {"element node tag unknown (4.1)", G41_HEAD G41_NODES
     "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 99\n$EndElements\n",
     TETMESH_ERR_RANGE},
    {"element node tag negative", G22_HEAD G22_NODES
     "$Elements\n1\n1 4 2 0 1 1 2 3 -4\n$EndElements\n",
     TETMESH_ERR_RANGE},
    {"node tag zero", G22_HEAD "$Nodes\n4\n0 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n"
                               G22_ELEMS,
     TETMESH_ERR_RANGE},
    {"degenerate tet", G22_HEAD "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 1 1 0\n$EndNodes\n"
                                G22_ELEMS,
     TETMESH_ERR_DEGENERATE},
};

static void test_gmsh_malformed(void)
{
    size_t i;
    for (i = 0; i < sizeof gmsh_bad / sizeof gmsh_bad[0]; i++) {
        tetmesh m;
        int rc;
        memset(&m, 0xab, sizeof m);
        rc = parse_gmsh(&m, gmsh_bad[i].text);
        CHECK_INT(gmsh_bad[i].expected, rc);
        CHECK(mesh_is_empty(&m));
        if (rc != gmsh_bad[i].expected || !mesh_is_empty(&m))
            fprintf(stderr, "    in case \"%s\"\n", gmsh_bad[i].name);
        if (rc == TETMESH_OK) tetmesh_free(&m);
    }
}

static void test_gmsh_valid_minimal(void)
{
    /* The bases the malformed cases are cut from parse. */
    tetmesh m;
    CHECK_INT(TETMESH_OK, parse_gmsh(&m, G22_HEAD G22_NODES G22_ELEMS));
    CHECK_INT(1, m.tet_count);
    tetmesh_free(&m);
    CHECK_INT(TETMESH_OK, parse_gmsh(&m, G41_HEAD G41_NODES G41_ELEMS));
    CHECK_INT(1, m.tet_count);
    tetmesh_free(&m);
    CHECK_INT(TETMESH_OK, parse_tetgen(&m, TG_NODE, TG_ELE));
    CHECK_INT(1, m.tet_count);
    tetmesh_free(&m);
}

static void test_gmsh_not_nul_terminated(void)
{
    const char text[] = G22_HEAD G22_NODES G22_ELEMS "$Comments\n";
    size_t full = sizeof text - 1, cut = full - strlen("$Comments\n");
    tetmesh m;
    CHECK_INT(TETMESH_OK, tetmesh_parse_gmsh(&m, text, cut));
    CHECK_INT(1, m.tet_count);
    tetmesh_free(&m);
    /* ending the text inside $EndElements truncates it */
    CHECK_INT(TETMESH_ERR_PARSE, tetmesh_parse_gmsh(&m, text, cut - 4));
    CHECK(mesh_is_empty(&m));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_parse_gmsh(&m, NULL, 0));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_parse_gmsh(NULL, text, cut));
}

static void test_gmsh_files(void)
{
    char path[512], missing[512];
    tetmesh m;
    temp_path(path, sizeof path, "files.msh");
    temp_path(missing, sizeof missing, "no_such_file.msh");
    REQUIRE(write_text_file(path, gmsh41_text));
    CHECK_INT(TETMESH_OK, tetmesh_read_gmsh(&m, path));
    CHECK_INT(5, m.node_count);
    CHECK_INT(2, m.tet_count);
    tetmesh_free(&m);
    remove(missing);
    CHECK_INT(TETMESH_ERR_IO, tetmesh_read_gmsh(&m, missing));
    CHECK(mesh_is_empty(&m));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_read_gmsh(&m, NULL));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_read_gmsh(NULL, path));
    remove(path);
}

/* >>writers */

static void test_write_vtk_mesh(void)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 2, 3};
    char path[512];
    char *text;
    const char *p;
    tetmesh m;
    double *pressure;
    float *velocity;
    tetmesh_field fields[2];
    int i, n = -1, size = -1, a = -1, b = -1, c = -1, d = -1, e = -1;
    double x = -1.0, y = -1.0, z = -1.0;
    temp_path(path, sizeof path, "mesh.vtk");
    REQUIRE(tetmesh_box(&m, lo, hi, 2, 1, 1, TETMESH_SPLIT6) == TETMESH_OK);
    pressure = (double *)malloc((size_t)m.node_count * sizeof(double));
    velocity = (float *)malloc((size_t)m.node_count * 3 * sizeof(float));
    REQUIRE(pressure && velocity);
    for (i = 0; i < m.node_count; i++) {
        pressure[i] = 0.1 * i + 1.0 / 3.0;
        velocity[3 * i] = (float)i;
        velocity[3 * i + 1] = -0.5f;
        velocity[3 * i + 2] = 1.0f / 3.0f;
    }
    fields[0].name = "pressure";
    fields[0].components = 1;
    fields[0].type = TETMESH_TYPE_OF(pressure[0]);
    fields[0].data = pressure;
    fields[1].name = "velocity";
    fields[1].components = 3;
    fields[1].type = TETMESH_TYPE_OF(velocity[0]);
    fields[1].data = velocity;
    CHECK_INT(TETMESH_OK, tetmesh_write_vtk(path, m.nodes, TETMESH_DOUBLE, m.node_count, m.tets,
                                            m.tet_count, fields, 2));
    text = read_text_file(path);
    REQUIRE(text != NULL);
    CHECK(strncmp(text, "# vtk DataFile Version 3.0\n", 27) == 0);
    CHECK(find_line(text, "ASCII") != NULL);
    CHECK(find_line(text, "DATASET UNSTRUCTURED_GRID") != NULL);
    CHECK(find_line(text, "POINTS 12 double") != NULL);
    p = after_line(text, "POINTS");
    CHECK(p && sscanf(p, "%lf %lf %lf", &x, &y, &z) == 3);
    CHECK_NEAR(0.0, x, 0.0);
    p = find_line(text, "CELLS");
    CHECK(p && sscanf(p, "CELLS %d %d", &n, &size) == 2);
    CHECK_INT(12, n);
    CHECK_INT(60, size);
    p = after_line(text, "CELLS");
    CHECK(p && sscanf(p, "%d %d %d %d %d", &a, &b, &c, &d, &e) == 5);
    CHECK_INT(4, a);
    CHECK_INT(m.tets[0], b);
    CHECK_INT(m.tets[3], e);
    CHECK(find_line(text, "CELL_TYPES 12") != NULL);
    CHECK_INT(12, count_lines_starting(after_line(text, "CELL_TYPES"), "10\n"));
    CHECK(find_line(text, "POINT_DATA 12") != NULL);
    CHECK(find_line(text, "SCALARS pressure double 1") != NULL);
    p = after_line(text, "LOOKUP_TABLE default");
    CHECK(p && sscanf(p, "%lf", &x) == 1);
    CHECK(x == pressure[0]); /* printed with enough digits to read back exactly */
    p = after_line(text, "VECTORS velocity float");
    p = skip_lines(p, 11); /* node 11 */
    CHECK(p && sscanf(p, "%lf %lf %lf", &x, &y, &z) == 3);
    CHECK(x == 11.0 && y == -0.5 && (float)z == velocity[35]);
    /* node 11 is grid node (2, 1, 1) */
    p = after_line(text, "POINTS");
    p = skip_lines(p, 11);
    CHECK(p && sscanf(p, "%lf %lf %lf", &x, &y, &z) == 3);
    CHECK(x == 1.0 && y == 2.0 && z == 3.0);
    free(text);
    free(pressure);
    free(velocity);
    tetmesh_free(&m);
    remove(path);
}

static void test_write_vtk_point_cloud(void)
{
    const float points[9] = {0.1f, 0.2f, 0.3f, 1, 2, 3, -1, -2, -3.5f};
    char path[512];
    char *text;
    const char *p;
    double x = -1.0, y = -1.0, z = -1.0;
    temp_path(path, sizeof path, "cloud.vtk");
    CHECK_INT(TETMESH_OK, tetmesh_write_vtk(path, points, TETMESH_TYPE_OF(points[0]), 3, NULL, 0,
                                            NULL, 0));
    text = read_text_file(path);
    REQUIRE(text != NULL);
    CHECK(find_line(text, "POINTS 3 float") != NULL);
    CHECK(find_line(text, "CELLS 3 6") != NULL);
    CHECK(find_line(text, "CELL_TYPES 3") != NULL);
    CHECK_INT(3, count_lines_starting(after_line(text, "CELL_TYPES"), "1\n"));
    CHECK(find_line(text, "POINT_DATA") == NULL);
    p = after_line(text, "POINTS");
    CHECK(p && sscanf(p, "%lf %lf %lf", &x, &y, &z) == 3);
    CHECK((float)x == points[0] && (float)y == points[1] && (float)z == points[2]);
    free(text);
    remove(path);
}

static void test_write_obj(void)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    char path[512];
    char *text;
    const char *p;
    tetmesh m;
    int *tris = NULL, tri_count = 0, a = 0, b = 0, c = 0, min_index = 1 << 30, max_index = 0;
    temp_path(path, sizeof path, "surface.obj");
    REQUIRE(tetmesh_box(&m, lo, hi, 2, 2, 2, TETMESH_SPLIT5) == TETMESH_OK);
    REQUIRE(tetmesh_boundary(m.tets, m.tet_count, m.node_count, &tris, &tri_count) ==
            TETMESH_OK);
    CHECK_INT(TETMESH_OK,
              tetmesh_write_obj(path, m.nodes, TETMESH_DOUBLE, m.node_count, tris, tri_count));
    text = read_text_file(path);
    REQUIRE(text != NULL);
    CHECK_INT(m.node_count, count_lines_starting(text, "v "));
    CHECK_INT(tri_count, count_lines_starting(text, "f "));
    CHECK_INT(48, tri_count);
    p = find_line(text, "f ");
    CHECK(p && sscanf(p, "f %d %d %d", &a, &b, &c) == 3);
    CHECK_INT(tris[0] + 1, a);
    CHECK_INT(tris[1] + 1, b);
    CHECK_INT(tris[2] + 1, c);
    for (p = find_line(text, "f "); p; p = find_line(p + 1, "f ")) {
        if (sscanf(p, "f %d %d %d", &a, &b, &c) != 3) break;
        if (a < min_index) min_index = a;
        if (b < min_index) min_index = b;
        if (c < min_index) min_index = c;
        if (a > max_index) max_index = a;
        if (b > max_index) max_index = b;
        if (c > max_index) max_index = c;
    }
    CHECK(min_index >= 1 && max_index <= m.node_count);
    free(text);
    free(tris);
    tetmesh_free(&m);
    remove(path);
}

static void test_writer_errors(void)
{
    const double points[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const int tet[4] = {0, 1, 2, 3}, bad_tet[4] = {0, 1, 2, 4}, tri[3] = {0, 2, 1};
    const double scalar[4] = {1, 2, 3, 4};
    tetmesh_field field;
    char path[512], bad_dir[512];
    FILE *f;
    temp_path(path, sizeof path, "errors.vtk");
    temp_path(bad_dir, sizeof bad_dir, "no_such_dir/x.vtk");
    field.name = "has space";
    field.components = 1;
    field.type = TETMESH_DOUBLE;
    field.data = scalar;
    remove(path);
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_write_vtk(NULL, points, 0, 4, tet, 1, NULL, 0));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_write_vtk(path, NULL, 0, 4, tet, 1, NULL, 0));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_write_vtk(path, points, 7, 4, tet, 1, NULL, 0));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_write_vtk(path, points, 0, 0, tet, 1, NULL, 0));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_write_vtk(path, points, 0, 4, NULL, 1, NULL, 0));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_write_vtk(path, points, 0, 4, tet, 1, NULL, 1));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_write_vtk(path, points, 0, 4, tet, 1, &field, 1));
    field.name = "ok";
    field.components = 2;
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_write_vtk(path, points, 0, 4, tet, 1, &field, 1));
    CHECK_INT(TETMESH_ERR_RANGE, tetmesh_write_vtk(path, points, 0, 4, bad_tet, 1, NULL, 0));
    f = fopen(path, "rb");
    CHECK(f == NULL); /* refused before the file was created */
    if (f) fclose(f);
    CHECK_INT(TETMESH_ERR_IO, tetmesh_write_vtk(bad_dir, points, 0, 4, tet, 1, NULL, 0));
    CHECK_INT(TETMESH_ERR_ARG, tetmesh_write_obj(path, points, 0, 4, NULL, 1));
    CHECK_INT(TETMESH_ERR_RANGE, tetmesh_write_obj(path, points, 0, 2, tri, 1));
    CHECK_INT(TETMESH_ERR_IO, tetmesh_write_obj(bad_dir, points, 0, 4, tri, 1));
}

static void test_error_strings(void)
{
    CHECK(strcmp(tetmesh_error_string(TETMESH_OK), "ok") == 0);
    CHECK(strcmp(tetmesh_error_string(TETMESH_ERR_PARSE), "unknown error") != 0);
    CHECK(strcmp(tetmesh_error_string(TETMESH_ERR_DEGENERATE), "unknown error") != 0);
    CHECK(strcmp(tetmesh_error_string(-100), "unknown error") == 0);
}

static const test_case cases[] = {
    TEST(test_box_split5),
    TEST(test_box_split6),
    TEST(test_box_node_numbering),
    TEST(test_box_bad_arguments),
    TEST(test_beam_extents),
    TEST(test_cylinder_conforming_positive),
    TEST(test_cylinder_volume_convergence),
    TEST(test_cylinder_bad_arguments),
    TEST(test_ellipsoid),
    TEST(test_hexmesh_grid),
    TEST(test_tetgen_round_trip_zero_based),
    TEST(test_tetgen_round_trip_one_based),
    TEST(test_tetgen_flips_negative_tet),
    TEST(test_tetgen_ten_node_tets),
    TEST(test_tetgen_not_nul_terminated),
    TEST(test_tetgen_malformed),
    TEST(test_tetgen_embedded_nul),
    TEST(test_tetgen_null_arguments),
    TEST(test_tetgen_files),
    TEST(test_gmsh22_mixed_elements),
    TEST(test_gmsh41_blocks_and_tags),
    TEST(test_gmsh22_round_trip),
    TEST(test_gmsh41_round_trip),
    TEST(test_gmsh_crlf_and_no_final_newline),
    TEST(test_gmsh_valid_minimal),
    TEST(test_gmsh_malformed),
    TEST(test_gmsh_not_nul_terminated),
    TEST(test_gmsh_files),
    TEST(test_write_vtk_mesh),
    TEST(test_write_vtk_point_cloud),
    TEST(test_write_obj),
    TEST(test_writer_errors),
    TEST(test_error_strings),
};

int main(int argc, char **argv) { return TEST_MAIN(argc, argv, cases); }
