/* compile_all.h - shared body of test_compile_all.c and test_compile_static.c: every model
   header and tetmesh.h with their implementations in one translation unit (built as C99
   and as C++, double and float, by the Makefile), included twice to prove the
   implementation guards, plus a smoke run of each model. The including file decides
   whether the *_STATIC macros are defined. Add each new model header here. */
#define TENSORMASS_IMPLEMENTATION
#include "../tensormass.h"
#include "../tensormass.h"
#define HEML_IMPLEMENTATION
#include "../heml.h"
#include "../heml.h"
#define FRAMES_IMPLEMENTATION
#include "../frames.h"
#include "../frames.h"
#define TETMESH_IMPLEMENTATION
#include "../examples/tetmesh.h"
#include "../examples/tetmesh.h"
#include "test.h"

static void test_tensormass_smoke(void)
{
    tetmesh mesh;
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    tmass_real *x;
    tmass_desc d = tmass_default_desc();
    tmass_model *m;
    int i;
    REQUIRE(tetmesh_box(&mesh, lo, hi, 2, 2, 2, TETMESH_SPLIT6) == TETMESH_OK);
    x = (tmass_real *)calloc((size_t)3 * 27, sizeof(tmass_real));
    for (i = 0; i < 3 * mesh.node_count; i++) x[i] = (tmass_real)mesh.nodes[i];
    d.rest_positions = x;
    d.node_count = mesh.node_count;
    d.tets = mesh.tets;
    d.tet_count = mesh.tet_count;
    CHECK_INT(TMASS_OK, tmass_create(&d, &m));
    if (m) {
        tmass_fix_node(m, 0);
        CHECK_INT(TMASS_OK, tmass_step(m));
        CHECK(tmass_positions(m)[3 * 26 + 2] < (tmass_real)1.0);
        tmass_destroy(m);
    }
    free(x);
    tetmesh_free(&mesh);
}

static void test_heml_smoke(void)
{
    tetmesh mesh;
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    heml_real *x;
    heml_desc d = heml_default_desc();
    heml_model *m;
    int i;
    REQUIRE(tetmesh_box(&mesh, lo, hi, 2, 2, 2, TETMESH_SPLIT6) == TETMESH_OK);
    x = (heml_real *)calloc((size_t)3 * 27, sizeof(heml_real));
    for (i = 0; i < 3 * mesh.node_count; i++) x[i] = (heml_real)mesh.nodes[i];
    d.rest_positions = x;
    d.node_count = mesh.node_count;
    d.tets = mesh.tets;
    d.tet_count = mesh.tet_count;
    CHECK_INT(HEML_OK, heml_create(&d, &m));
    if (m) {
        heml_fix_node(m, 0);
        CHECK_INT(HEML_OK, heml_step(m));
        CHECK_INT(HEML_OK, heml_step_ex(m, (heml_real)1e-2, HEML_IMPLICIT_EULER));
        CHECK(heml_positions(m)[3 * 26 + 2] < (heml_real)1.0);
        heml_destroy(m);
    }
    free(x);
    tetmesh_free(&mesh);
}

static void test_frames_smoke(void)
{
    tetmesh mesh;
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    frm_real *x;
    frm_sampling s;
    frm_desc d = frm_model_default_desc();
    frm_model *m;
    int i;
    REQUIRE(tetmesh_box(&mesh, lo, hi, 2, 2, 2, TETMESH_SPLIT6) == TETMESH_OK);
    x = (frm_real *)calloc((size_t)3 * 27, sizeof(frm_real));
    for (i = 0; i < 3 * mesh.node_count; i++) x[i] = (frm_real)mesh.nodes[i];
    REQUIRE(frm_sampling_tets(&s, x, mesh.node_count, mesh.tets, mesh.tet_count, 1, NULL, NULL) == FRM_OK);
    frm_sampling_apply(&s, &d);
    CHECK_INT(FRM_OK, frm_model_create(&d, &m));
    if (m) {
        frm_model_fix_frame(m, 0);
        CHECK_INT(FRM_OK, frm_model_step(m));
        CHECK(frm_model_positions(m)[3 * 26 + 2] < (frm_real)1.0);
        frm_model_destroy(m);
    }
    frm_sampling_free(&s);
    free(x);
    tetmesh_free(&mesh);
}

static const test_case cases[] = {
    TEST(test_tensormass_smoke),
    TEST(test_heml_smoke),
    TEST(test_frames_smoke),
};

int main(int argc, char **argv) { return TEST_MAIN(argc, argv, cases); }
