/* test_tetmesh.c - tests of examples/tetmesh.h: generators (box, beam, cylinder, hex
   grid).

   Each case is listed in the table at the end and run by test_main() (tests/test.h):

       static void test_box_split6(void) { ... CHECK_INT(TETMESH_OK, rc); ... }
       static const test_case cases[] = { TEST(test_box_split6), ... };
       int main(int argc, char **argv) { return TEST_MAIN(argc, argv, cases); }

   `./test_tetmesh cylinder` runs the cases whose name contains "cylinder".

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

static int mesh_is_empty(const tetmesh *m)
{
    return m->nodes == NULL && m->tets == NULL && m->node_count == 0 && m->tet_count == 0;
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
    TEST(test_hexmesh_grid),
    TEST(test_error_strings),
};

int main(int argc, char **argv) { return TEST_MAIN(argc, argv, cases); }
