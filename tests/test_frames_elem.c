/* Tests of frames.h's element parts for issue 18 ("no silent wrong answers"): creation
   from a description not made by its default function, the float renames of every
   entry point, shape functions and samplings refusing what their docs forbid, St
   Venant-Kirchhoff refusing mirrored samples, and the rotation stabilisation that ties
   every frame's rotation to the material's (no spurious low modes on tetrahedral frames,
   no zero-energy rotations on hexahedral frames one cell across). */
#define FRAMES_IMPLEMENTATION
#include "../frames.h"
#define TETMESH_IMPLEMENTATION
#include "../examples/tetmesh.h"
#include "test.h"

#define IS_FLOAT (sizeof(frm_real) == sizeof(float))

static frm_real *alloc_reals(int count)
{
    return (frm_real *)calloc(count > 0 ? (size_t)count : 1, sizeof(frm_real));
}

/* ---- item 12: a description not made by its default function ---------------------- */

/* A description filled with 0xA5 bytes (what a stack struct holds before anyone sets it)
   is refused with FRM_ERR_DESC: its log callback is garbage and must not be called. */
static void test_garbage_descriptions(void)
{
    frm_desc d;
    frm_shape_desc sh;
    frm_poisson_desc p;
    frm_sampling s;
    frm_model *m = (frm_model *)&m;
    frm_real frames[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, samples[3] = {(frm_real)0.2, (frm_real)0.2, (frm_real)0.2};
    frm_real lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    memset(&d, 0xA5, sizeof d);
    CHECK_INT(FRM_ERR_DESC, frm_model_create(&d, &m));
    CHECK(m == NULL);
    memset(&sh, 0xA5, sizeof sh);
    CHECK_INT(FRM_ERR_DESC, frm_sampling_meshless(&s, frames, 4, samples, 1, 1, &sh, NULL));
    CHECK(s.frame_count == 0 && s.frame_positions == NULL);
    memset(&p, 0xA5, sizeof p);
    CHECK_INT(FRM_ERR_DESC, frm_sampling_box(&s, lo, hi, &p, NULL, NULL));
    p = frm_poisson_default_desc();
    CHECK_INT(FRM_ERR_DESC, frm_sampling_box(&s, lo, hi, &p, &sh, NULL));
    {
        /* a closed surface (a tetrahedron) */
        frm_real v[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
        int tri[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
        memset(&p, 0xA5, sizeof p);
        CHECK_INT(FRM_ERR_DESC, frm_sampling_surface(&s, v, 4, tri, 4, &p, NULL, NULL));
        p = frm_poisson_default_desc();
        CHECK_INT(FRM_ERR_DESC, frm_sampling_surface(&s, v, 4, tri, 4, &p, &sh, NULL));
    }
    /* a copy of a default description stays valid */
    sh = frm_shape_default_desc();
    CHECK_INT(FRM_OK, frm_sampling_meshless(&s, frames, 4, samples, 1, 1, &sh, NULL));
    frm_sampling_free(&s);
}

/* ---- item 8: every entry point renamed in float builds ---------------------------- */

#define STR2(x) #x
#define STR(x) STR2(x)
#define NAME(f) {#f, STR(f)}
typedef struct entry_name {
    const char *plain, *expanded;
} entry_name;

/* Every FRMDEF function of frames.h: the name after macro expansion carries _f32 in float
   builds and is unchanged in double builds. The header's own list is read back from
   frames.h below, so a function added later without a rename fails here. */
static void test_float_renames(void)
{
    static const entry_name names[] = {
        NAME(frm_version), NAME(frm_error_string), NAME(frm_shape_tet), NAME(frm_shape_hex), NAME(frm_shape_shepard),
        NAME(frm_shape_mls), NAME(frm_sampling_hexes), NAME(frm_sampling_tets), NAME(frm_sampling_meshless),
        NAME(frm_sampling_curve), NAME(frm_material_thin),
        NAME(frm_sampling_box), NAME(frm_sampling_surface), NAME(frm_sampling_apply), NAME(frm_sampling_free),
        NAME(frm_shape_default_desc), NAME(frm_poisson_default_desc), NAME(frm_model_default_desc),
        NAME(frm_model_create), NAME(frm_model_destroy), NAME(frm_model_fix_frame), NAME(frm_model_drive_frame),
        NAME(frm_model_release_frame), NAME(frm_model_frame_state), NAME(frm_model_set_external),
        NAME(frm_model_clear_external), NAME(frm_model_set_gravity), NAME(frm_model_set_solver),
        NAME(frm_model_set_stiffness_mode), NAME(frm_model_step), NAME(frm_model_step_ex), NAME(frm_model_solve_static),
        NAME(frm_model_newton_step), NAME(frm_model_frame_count), NAME(frm_model_sample_count),
        NAME(frm_model_pair_count), NAME(frm_model_positions), NAME(frm_model_orientations),
        NAME(frm_model_velocities), NAME(frm_model_set_poses), NAME(frm_model_set_velocities),
        NAME(frm_model_sample_positions), NAME(frm_model_deformation_gradients), NAME(frm_model_forces),
        NAME(frm_model_total_forces), NAME(frm_model_energy), NAME(frm_model_last_stats), NAME(frm_model_linear_solver), NAME(frm_model_mass_block),
        NAME(frm_model_memory_bytes), NAME(frm_model_stabilized_frames), NAME(frm_model_view), NAME(frm_model_prepare_stiffness),
        NAME(frm_model_apply_stiffness), NAME(frm_model_assemble_stiffness), NAME(frm_model_stiffness_blocks),
        NAME(frm_model_stiffness_block), NAME(frm_model_set_frame_axes), NAME(frm_model_frame_axes),
        NAME(frm_model_set_damping), NAME(frm_model_set_integrator), NAME(frm_model_displacements), NAME(frm_model_rest_positions),
        NAME(frm_part_default), NAME(frm_rigid_body_default), NAME(frm_parts_combine), NAME(frm_assembly_apply), NAME(frm_assembly_free),
        NAME(frm_probe_default_desc), NAME(frm_probe_create), NAME(frm_probe_positions), NAME(frm_probe_displacements),
        NAME(frm_probe_velocities), NAME(frm_probe_count), NAME(frm_probe_jacobian), NAME(frm_probe_jacobian_transpose),
        NAME(frm_probe_add_external), NAME(frm_model_set_anchors), NAME(frm_probe_destroy), NAME(frm_modal_default_desc),
        NAME(frm_modal_create), NAME(frm_modal_solve), NAME(frm_modal_count), NAME(frm_modal_frequency),
        NAME(frm_modal_shape), NAME(frm_modal_destroy), NAME(frm_btd_factor_size), NAME(frm_btd_factor),
        NAME(frm_btd_solve), NAME(frm_btd_compliance), NAME(frm_qp_box), NAME(frm_chain_default_desc),
        NAME(frm_chain_create), NAME(frm_chain_destroy), NAME(frm_chain_frame_count), NAME(frm_chain_actuator_count),
        NAME(frm_chain_positions), NAME(frm_chain_orientations), NAME(frm_chain_velocities), NAME(frm_chain_efforts),
        NAME(frm_chain_set_poses), NAME(frm_chain_set_base), NAME(frm_chain_set_external), NAME(frm_chain_set_gravity),
        NAME(frm_chain_set_efforts), NAME(frm_chain_forces), NAME(frm_chain_energy), NAME(frm_chain_apply_stiffness),
        NAME(frm_chain_actuator_measures), NAME(frm_chain_effector), NAME(frm_chain_solve_static), NAME(frm_chain_step),
        NAME(frm_chain_inverse_step), NAME(frm_chain_inverse_solve), NAME(frm_chain_link_compliance)};
    int count = (int)(sizeof names / sizeof names[0]), i, declared = 0, renamed = 0;
    char line[1024];
    FILE *f;
    for (i = 0; i < count; i++) {
        char want[128];
        snprintf(want, sizeof want, "%s%s", names[i].plain, IS_FLOAT ? "_f32" : "");
        if (strcmp(want, names[i].expanded) != 0) {
            fprintf(stderr, "    %s expands to %s\n", names[i].plain, names[i].expanded);
            CHECK(0);
        }
    }
    /* every function declared FRMDEF in the header's public part has a rename line
       "#define name name_f32" and is in the list above */
    f = fopen("frames.h", "r");
    if (!f) f = fopen("../frames.h", "r");
    if (!f) {
        printf("    frames.h not found from the working directory: the header scan is skipped\n");
        return;
    }
    {
        char (*decl)[64] = (char (*)[64])calloc(512, 64), (*ren)[64] = (char (*)[64])calloc(512, 64);
        while (fgets(line, sizeof line, f)) {
            if (strstr(line, "#endif /* FRAMES_H */")) break;
            if (strncmp(line, "FRMDEF ", 7) == 0) {
                char *paren = strchr(line, '('), *start;
                if (!paren) continue;
                start = paren;
                while (start > line && (start[-1] == '_' || (start[-1] >= 'a' && start[-1] <= 'z') ||
                                        (start[-1] >= '0' && start[-1] <= '9')))
                    start--;
                if (declared < 512 && paren - start < 63) {
                    memcpy(decl[declared], start, (size_t)(paren - start));
                    declared++;
                }
            } else {
                char a[64], b[80];
                if (sscanf(line, "#define %63s %79s", a, b) == 2 && strncmp(a, "frm_", 4) == 0) {
                    size_t la = strlen(a);
                    if (strncmp(a, b, la) == 0 && strcmp(b + la, "_f32") == 0 && renamed < 512) strcpy(ren[renamed++], a);
                }
            }
        }
        fclose(f);
        CHECK(declared > 0);
        for (i = 0; i < declared; i++) {
            int k, found = 0, listed = 0;
            for (k = 0; k < renamed; k++) found |= strcmp(decl[i], ren[k]) == 0;
            for (k = 0; k < count; k++) listed |= strcmp(decl[i], names[k].plain) == 0;
            if (!found || !listed) {
                fprintf(stderr, "    %s: %s\n", decl[i], !found ? "no float rename in frames.h" : "missing from this test's list");
                CHECK(0);
            }
        }
        printf("    %d entry points declared, %d renamed in float builds\n", declared, renamed);
        CHECK_INT(declared, renamed);
        free(decl);
        free(ren);
    }
}

/* ---- item 15: shape functions and samplings refuse what the docs forbid ------------ */

static void test_shape_refusals(void)
{
    frm_real nan_ = (frm_real)NAN, inf_ = (frm_real)INFINITY;
    frm_real tet[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, hex[24], w[64], g[192], pt[3], x[3];
    frm_real fr[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    int a, k;
    for (a = 0; a < 8; a++)
        for (k = 0; k < 3; k++) hex[3 * a + k] = (frm_real)((a >> k) & 1);
    for (k = 0; k < 3; k++) {
        frm_real bad[2];
        int b;
        bad[0] = nan_;
        bad[1] = inf_;
        for (b = 0; b < 2; b++) {
            pt[0] = pt[1] = pt[2] = (frm_real)0.2;
            pt[k] = bad[b];
            CHECK_INT(FRM_ERR_ARG, frm_shape_tet(tet, pt, w, g));
            CHECK_INT(FRM_ERR_ARG, frm_shape_shepard(fr, 4, pt, 2, 0, w, g));
            CHECK_INT(FRM_ERR_ARG, frm_shape_shepard(fr, 4, pt, 2, 3, w, g));
            CHECK_INT(FRM_ERR_ARG, frm_shape_mls(fr, 4, pt, 3, w, g));
            x[0] = x[1] = x[2] = (frm_real)0.5;
            x[k] = bad[b];
            CHECK_INT(FRM_ERR_ARG, frm_shape_hex(hex, x, pt, w, g, NULL));
        }
    }
    /* non-finite corners or frames */
    pt[0] = pt[1] = pt[2] = (frm_real)0.2;
    tet[4] = nan_;
    CHECK_INT(FRM_ERR_ARG, frm_shape_tet(tet, pt, w, g));
    tet[4] = 0;
    hex[7] = inf_;
    x[0] = x[1] = x[2] = (frm_real)0.5;
    CHECK_INT(FRM_ERR_ARG, frm_shape_hex(hex, x, pt, w, g, NULL));
    hex[7] = 0;
    fr[5] = nan_;
    CHECK_INT(FRM_ERR_ARG, frm_shape_shepard(fr, 4, pt, 2, 0, w, g));
    CHECK_INT(FRM_ERR_ARG, frm_shape_mls(fr, 4, pt, 3, w, g));
    fr[5] = 0;
    /* the exponent must exceed 1 (the limit on a frame needs it), radius finite */
    CHECK_INT(FRM_ERR_ARG, frm_shape_shepard(fr, 4, pt, (frm_real)0.5, 0, w, g));
    CHECK_INT(FRM_ERR_ARG, frm_shape_shepard(fr, 4, pt, 1, 0, w, g));
    CHECK_INT(FRM_ERR_ARG, frm_shape_shepard(fr, 4, pt, nan_, 0, w, g));
    CHECK_INT(FRM_ERR_ARG, frm_shape_shepard(fr, 4, pt, 2, nan_, w, g));
    CHECK_INT(FRM_ERR_ARG, frm_shape_mls(fr, 4, pt, inf_, w, g));
    CHECK_INT(FRM_OK, frm_shape_shepard(fr, 4, pt, (frm_real)1.5, 0, w, g));
    CHECK_INT(FRM_OK, frm_shape_tet(tet, pt, w, g));
    {
        frm_shape_desc sh = frm_shape_default_desc();
        frm_poisson_desc p = frm_poisson_default_desc();
        frm_sampling s;
        frm_real smp[3] = {(frm_real)0.2, (frm_real)0.2, (frm_real)0.2}, lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
        sh.power = (frm_real)0.5;
        CHECK_INT(FRM_ERR_SAMPLING, frm_sampling_meshless(&s, fr, 4, smp, 1, 1, &sh, NULL));
        sh.power = 1;
        CHECK_INT(FRM_ERR_SAMPLING, frm_sampling_meshless(&s, fr, 4, smp, 1, 1, &sh, NULL));
        CHECK_INT(FRM_ERR_SAMPLING, frm_sampling_box(&s, lo, hi, &p, &sh, NULL));
        sh = frm_shape_default_desc();
        p.frame_spacing = (frm_real)0.1;
        p.sample_spacing = (frm_real)0.2;
        CHECK_INT(FRM_ERR_SAMPLING, frm_sampling_box(&s, lo, hi, &p, &sh, NULL));
        CHECK(s.frame_count == 0);
        p.frame_spacing = (frm_real)0.4;
        CHECK_INT(FRM_OK, frm_sampling_box(&s, lo, hi, &p, &sh, NULL));
        frm_sampling_free(&s);
    }
}

/* ---- item 5: St Venant-Kirchhoff refuses mirrored samples -------------------------- */

/* A unit cube of 2 x 2 x 4 hexahedral cells, St Venant-Kirchhoff (E = 10 kPa, nu = 0.3),
   compressed to s = 0.5 in one static solve: the bottom face's frames at (t x, t y, 0),
   the top face's at (t x, t y, s) with t the lateral stretch of the uniaxial state
   (S_xx = 0: E_xx = -nu E_zz), so the homogeneous state F = diag(t, t, s) is the
   equilibrium and P_zz = E/2 (s^3 - s) (REFERENCES R4). Putting the top frames at their
   targets turns the top layer (z from 0.75 to 1) into a mirrored one, F_zz = -1, where
   SVK's energy has a minimum of zero: the solver once returned success with that layer
   mirrored and P_zz = 0. Now a sample with det F <= 0 is refused: the solve lands on the
   closed form with every det F > 0, or returns an error and keeps its state. */
static void test_svk_mirrored_compression(void)
{
    hexmesh h;
    frm_sampling s;
    frm_desc d = frm_model_default_desc();
    frm_model *m;
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, E = 1e4, nu = 0.3, sz = 0.5, Ezz = 0.5 * (sz * sz - 1), t, Pzz;
    frm_real *x, q[4] = {0, 0, 0, 1};
    const frm_real *F;
    int i, err, minus = 0;
    t = sqrt(1 + 2 * (-nu * Ezz));
    REQUIRE(hexmesh_grid(&h, lo, hi, 2, 2, 4) == TETMESH_OK);
    x = alloc_reals(3 * h.node_count);
    for (i = 0; i < 3 * h.node_count; i++) x[i] = (frm_real)h.nodes[i];
    REQUIRE(frm_sampling_hexes(&s, x, h.node_count, h.hexes, h.hex_count, 2, FRM_QUADRATURE_SUBCELL, NULL) == FRM_OK);
    frm_sampling_apply(&s, &d);
    d.material.law = FRM_LAW_SVK;
    d.material.young_modulus = (frm_real)E;
    d.material.poisson_ratio = (frm_real)nu;
    d.gravity[2] = 0;
    REQUIRE(frm_model_create(&d, &m) == FRM_OK);
    for (i = 0; i < h.node_count; i++) {
        frm_real target[3];
        double z = h.nodes[3 * i + 2];
        if (z != 0 && z != 1) continue;
        target[0] = (frm_real)(t * (h.nodes[3 * i] - 0.5) + 0.5);
        target[1] = (frm_real)(t * (h.nodes[3 * i + 1] - 0.5) + 0.5);
        target[2] = (frm_real)(sz * z);
        REQUIRE(frm_model_drive_frame(m, i, target, q) == FRM_OK);
    }
    err = frm_model_solve_static(m);
    F = frm_model_deformation_gradients(m);
    for (i = 0; i < s.sample_count; i++) {
        const frm_real *f = F + 9 * i;
        double det = f[0] * ((double)f[4] * f[8] - (double)f[5] * f[7]) - f[1] * ((double)f[3] * f[8] - (double)f[5] * f[6]) +
                     f[2] * ((double)f[3] * f[7] - (double)f[4] * f[6]);
        minus += !(det > 0);
    }
    if (err == FRM_OK) {
        const frm_real *fi;
        double fz = 0, expect = 0.5 * E * (sz * sz * sz - sz);
        REQUIRE(frm_model_forces(m, &fi) == FRM_OK);
        for (i = 0; i < h.node_count; i++)
            if (h.nodes[3 * i + 2] == 1) fz += (double)fi[6 * i + 2];
        Pzz = -fz / 1.0; /* reference area 1 m^2 */
        printf("    SVK cube to s = 0.5 in one call: success, P_zz %.2f Pa (R4 %.2f), %d mirrored samples\n", Pzz, expect, minus);
        CHECK_INT(0, minus);
        CHECK_REL(expect, Pzz, IS_FLOAT ? 1e-3 : 1e-5);
    } else {
        printf("    SVK cube to s = 0.5 in one call: %s (state kept: %d mirrored samples)\n", frm_error_string(err), minus);
        CHECK(err == FRM_ERR_INVERTED || err == FRM_ERR_NO_CONVERGENCE || err == FRM_ERR_STALLED);
        CHECK_INT(0, minus); /* the rest state was kept */
    }
    frm_model_destroy(m);
    frm_sampling_free(&s);
    free(x);
    hexmesh_free(&h);
}


/* The implicit step too: one St Venant-Kirchhoff cell (2^3 samples) with its bottom frames
   fixed and a top corner driven through the bottom face in one step (the bench's squash):
   the step returns FRM_ERR_INVERTED and keeps its state, or ends with every det F > 0. */
static void test_svk_mirrored_step(void)
{
    hexmesh h;
    frm_sampling s;
    frm_desc d = frm_model_default_desc();
    frm_model *m;
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    frm_real *x, q[4] = {0, 0, 0, 1}, target[3] = {-0.5f, -0.5f, -0.5f}, before[3];
    const frm_real *F;
    int i, err, corner = -1, minus = 0;
    REQUIRE(hexmesh_grid(&h, lo, hi, 1, 1, 1) == TETMESH_OK);
    x = alloc_reals(3 * h.node_count);
    for (i = 0; i < 3 * h.node_count; i++) x[i] = (frm_real)h.nodes[i];
    REQUIRE(frm_sampling_hexes(&s, x, h.node_count, h.hexes, h.hex_count, 2, FRM_QUADRATURE_SUBCELL, NULL) == FRM_OK);
    frm_sampling_apply(&s, &d);
    d.material.law = FRM_LAW_SVK;
    d.gravity[2] = 0;
    REQUIRE(frm_model_create(&d, &m) == FRM_OK);
    for (i = 0; i < h.node_count; i++) {
        if (h.nodes[3 * i + 2] == 0) frm_model_fix_frame(m, i);
        if (h.nodes[3 * i] == 1 && h.nodes[3 * i + 1] == 1 && h.nodes[3 * i + 2] == 1) corner = i;
    }
    REQUIRE(corner >= 0);
    REQUIRE(frm_model_drive_frame(m, corner, target, q) == FRM_OK);
    for (i = 0; i < 3; i++) before[i] = frm_model_positions(m)[3 * corner + i];
    err = frm_model_step(m);
    F = frm_model_deformation_gradients(m);
    for (i = 0; i < s.sample_count; i++) {
        const frm_real *f = F + 9 * i;
        double det = f[0] * ((double)f[4] * f[8] - (double)f[5] * f[7]) - f[1] * ((double)f[3] * f[8] - (double)f[5] * f[6]) +
                     f[2] * ((double)f[3] * f[7] - (double)f[4] * f[6]);
        minus += !(det > 0);
    }
    printf("    SVK cell, a corner driven through the bottom in one implicit step: %s, %d mirrored samples\n",
           frm_error_string(err), minus);
    CHECK_INT(0, minus);
    if (err) {
        CHECK_INT(FRM_ERR_INVERTED, err);
        for (i = 0; i < 3; i++) CHECK(frm_model_positions(m)[3 * corner + i] == before[i]);
    }
    frm_model_destroy(m);
    frm_sampling_free(&s);
    free(x);
    hexmesh_free(&h);
}

/* ---- item 18: modes of the linearised model ----------------------------------------- */

/* Eigen-decomposition of a symmetric n x n matrix (row-major V in, eigenvectors out in its
   columns; d the eigenvalues, ascending): Householder tridiagonalisation and the implicit
   QL algorithm (EISPACK tred2 / tql2, after the public-domain JAMA translation). */
static void sym_eigen(double *V, int n, double *d)
{
    double *e = (double *)calloc((size_t)n, sizeof(double)), f, g, h, hh, scale, tst1, eps = pow(2.0, -52.0);
    int i, j, k, l, m, iter;
    for (j = 0; j < n; j++) d[j] = V[n * (n - 1) + j];
    for (i = n - 1; i > 0; i--) {
        scale = 0;
        h = 0;
        for (k = 0; k < i; k++) scale += fabs(d[k]);
        if (scale == 0) {
            e[i] = d[i - 1];
            for (j = 0; j < i; j++) {
                d[j] = V[n * (i - 1) + j];
                V[n * i + j] = 0;
                V[n * j + i] = 0;
            }
        } else {
            for (k = 0; k < i; k++) {
                d[k] /= scale;
                h += d[k] * d[k];
            }
            f = d[i - 1];
            g = sqrt(h);
            if (f > 0) g = -g;
            e[i] = scale * g;
            h = h - f * g;
            d[i - 1] = f - g;
            for (j = 0; j < i; j++) e[j] = 0;
            for (j = 0; j < i; j++) {
                f = d[j];
                V[n * j + i] = f;
                g = e[j] + V[n * j + j] * f;
                for (k = j + 1; k <= i - 1; k++) {
                    g += V[n * k + j] * d[k];
                    e[k] += V[n * k + j] * f;
                }
                e[j] = g;
            }
            f = 0;
            for (j = 0; j < i; j++) {
                e[j] /= h;
                f += e[j] * d[j];
            }
            hh = f / (h + h);
            for (j = 0; j < i; j++) e[j] -= hh * d[j];
            for (j = 0; j < i; j++) {
                f = d[j];
                g = e[j];
                for (k = j; k <= i - 1; k++) V[n * k + j] -= (f * e[k] + g * d[k]);
                d[j] = V[n * (i - 1) + j];
                V[n * i + j] = 0;
            }
        }
        d[i] = h;
    }
    for (i = 0; i < n - 1; i++) {
        V[n * (n - 1) + i] = V[n * i + i];
        V[n * i + i] = 1;
        h = d[i + 1];
        if (h != 0) {
            for (k = 0; k <= i; k++) d[k] = V[n * k + i + 1] / h;
            for (j = 0; j <= i; j++) {
                g = 0;
                for (k = 0; k <= i; k++) g += V[n * k + i + 1] * V[n * k + j];
                for (k = 0; k <= i; k++) V[n * k + j] -= g * d[k];
            }
        }
        for (k = 0; k <= i; k++) V[n * k + i + 1] = 0;
    }
    for (j = 0; j < n; j++) {
        d[j] = V[n * (n - 1) + j];
        V[n * (n - 1) + j] = 0;
    }
    V[n * (n - 1) + n - 1] = 1;
    e[0] = 0;
    /* tql2 */
    for (i = 1; i < n; i++) e[i - 1] = e[i];
    e[n - 1] = 0;
    f = 0;
    tst1 = 0;
    for (l = 0; l < n; l++) {
        tst1 = fmax(tst1, fabs(d[l]) + fabs(e[l]));
        m = l;
        while (m < n) {
            if (fabs(e[m]) <= eps * tst1) break;
            m++;
        }
        if (m > l) {
            iter = 0;
            do {
                double p, r, dl1, c, c2, c3, el1, s, s2;
                iter++;
                g = d[l];
                p = (d[l + 1] - g) / (2 * e[l]);
                r = hypot(p, 1.0);
                if (p < 0) r = -r;
                d[l] = e[l] / (p + r);
                d[l + 1] = e[l] * (p + r);
                dl1 = d[l + 1];
                h = g - d[l];
                for (i = l + 2; i < n; i++) d[i] -= h;
                f += h;
                p = d[m];
                c = 1;
                c2 = c;
                c3 = c;
                el1 = e[l + 1];
                s = 0;
                s2 = 0;
                for (i = m - 1; i >= l; i--) {
                    c3 = c2;
                    c2 = c;
                    s2 = s;
                    g = c * e[i];
                    h = c * p;
                    r = hypot(p, e[i]);
                    e[i + 1] = s * r;
                    s = e[i] / r;
                    c = p / r;
                    p = c * d[i] - s * g;
                    d[i + 1] = h + s * (c * g + s * d[i]);
                    for (k = 0; k < n; k++) {
                        h = V[n * k + i + 1];
                        V[n * k + i + 1] = s * V[n * k + i] + c * h;
                        V[n * k + i] = c * V[n * k + i] - s * h;
                    }
                }
                p = -s * s2 * c3 * el1 * e[l] / dl1;
                e[l] = s * p;
                d[l] = c * p;
            } while (fabs(e[l]) > eps * tst1 && iter < 60);
        }
        d[l] = d[l] + f;
        e[l] = 0;
    }
    for (i = 0; i < n - 1; i++) { /* sort ascending, vectors along */
        k = i;
        f = d[i];
        for (j = i + 1; j < n; j++)
            if (d[j] < f) {
                k = j;
                f = d[j];
            }
        if (k != i) {
            d[k] = d[i];
            d[i] = f;
            for (j = 0; j < n; j++) {
                f = V[n * j + i];
                V[n * j + i] = V[n * j + k];
                V[n * j + k] = f;
            }
        }
    }
    free(e);
}

/* The modes of the linearised model at its current state: K (symmetric part, built
   column by column from frm_model_apply_stiffness) and the generalized mass (6x6 blocks,
   frm_model_mass_block) on the free frames, A = M^-1/2 K M^-1/2 (M block-diagonal) and
   its eigenvalues lambda = omega^2. freq: 6 * free frames values (Hz, ascending; a negative
   lambda gives a negative frequency -sqrt(-lambda) / 2 pi). rot: the share of each of the
   lowest `nrot` modes' kinetic energy in the frames' rotations (x^T M_rr x / x^T M x per
   frame, summed), or NULL. Returns the number of modes. */
static int model_modes(frm_model *m, double *freq, double *rot, int nrot)
{
    int F = frm_model_frame_count(m), nf = 0, i, j, r, c, k, n, *free_ = (int *)malloc(sizeof(int) * (size_t)F);
    double *K, *L, *A, *Mb, pi = 3.14159265358979323846;
    frm_real *v = alloc_reals(6 * F), *out = alloc_reals(6 * F);
    for (i = 0; i < F; i++)
        if (frm_model_frame_state(m, i) == 0) free_[nf++] = i;
    n = 6 * nf;
    K = (double *)calloc((size_t)n * n, sizeof(double));
    A = (double *)calloc((size_t)n * n, sizeof(double));
    L = (double *)calloc((size_t)nf * 36, sizeof(double));
    Mb = (double *)calloc((size_t)nf * 36, sizeof(double));
    if (frm_model_prepare_stiffness(m) != FRM_OK) n = 0;
    for (j = 0; j < n; j++) {
        memset(v, 0, sizeof(frm_real) * 6 * (size_t)F);
        v[6 * free_[j / 6] + j % 6] = 1;
        frm_model_apply_stiffness(m, v, out, 1);
        for (i = 0; i < n; i++) K[(size_t)n * i + j] = (double)out[6 * free_[i / 6] + i % 6];
    }
    for (i = 0; i < n; i++)
        for (j = 0; j < i; j++) K[(size_t)n * i + j] = K[(size_t)n * j + i] = 0.5 * (K[(size_t)n * i + j] + K[(size_t)n * j + i]);
    for (i = 0; i < nf && n; i++) { /* L_i = M_i^-1/2 by its eigen-decomposition */
        double Mi[36], V[36], ev[6];
        frm_real mb[36];
        frm_model_mass_block(m, free_[i], mb);
        for (k = 0; k < 36; k++) Mi[k] = Mb[36 * i + k] = (double)mb[k];
        for (r = 0; r < 6; r++)
            for (c = 0; c < r; c++) Mi[6 * r + c] = Mi[6 * c + r] = 0.5 * (Mi[6 * r + c] + Mi[6 * c + r]);
        memcpy(V, Mi, sizeof V);
        sym_eigen(V, 6, ev);
        for (r = 0; r < 6; r++)
            for (c = 0; c < 6; c++) {
                double t = 0;
                for (k = 0; k < 6; k++) t += V[6 * r + k] * V[6 * c + k] / sqrt(ev[k]);
                L[36 * i + 6 * r + c] = t;
            }
    }
    for (i = 0; i < n; i++) /* A = L K L */
        for (j = 0; j < n; j++) {
            double t = 0;
            int bi = i / 6, bj = j / 6;
            for (r = 0; r < 6; r++) {
                double krow = 0;
                for (c = 0; c < 6; c++) krow += K[(size_t)n * (6 * bi + r) + 6 * bj + c] * L[36 * bj + 6 * c + j % 6];
                t += L[36 * bi + 6 * (i % 6) + r] * krow;
            }
            A[(size_t)n * i + j] = t;
        }
    for (i = 0; i < n; i++)
        for (j = 0; j < i; j++) A[(size_t)n * i + j] = A[(size_t)n * j + i] = 0.5 * (A[(size_t)n * i + j] + A[(size_t)n * j + i]);
    if (n) sym_eigen(A, n, K); /* K now holds the eigenvalues */
    for (i = 0; i < n; i++) freq[i] = (K[i] >= 0 ? sqrt(K[i]) : -sqrt(-K[i])) / (2 * pi);
    for (k = 0; rot && k < nrot && k < n; k++) { /* x = L y: kinetic shares */
        double tot = 0, rr = 0;
        for (i = 0; i < nf; i++) {
            double x[6], Mx[6];
            for (r = 0; r < 6; r++) {
                x[r] = 0;
                for (c = 0; c < 6; c++) x[r] += L[36 * i + 6 * r + c] * A[(size_t)n * (6 * i + c) + k];
            }
            for (r = 0; r < 6; r++) {
                Mx[r] = 0;
                for (c = 0; c < 6; c++) Mx[r] += Mb[36 * i + 6 * r + c] * x[c];
            }
            for (r = 0; r < 6; r++) tot += x[r] * Mx[r];
            for (r = 3; r < 6; r++) { /* the rotations alone: x_r^T J x_r */
                double t = 0;
                for (c = 3; c < 6; c++) t += Mb[36 * i + 6 * r + c] * x[c];
                rr += x[r] * t;
            }
        }
        rot[k] = tot > 0 ? rr / tot : 0;
    }
    free(free_);
    free(v);
    free(out);
    free(K);
    free(A);
    free(L);
    free(Mb);
    return n;
}

/* The R3 beam (1 x 0.1 x 0.1 m, E = 1 MPa, nu = 0.3, rho = 1000) of 10 k x k x k cubes, 5
   tetrahedra each, one sample per tetrahedron (the bench's tet4 body), clamped at x = 0,
   no gravity. */
static int tet_beam(frm_sampling *s, frm_model **m, int k, double gamma)
{
    tetmesh t;
    frm_desc d = frm_model_default_desc();
    frm_real *x;
    int i, err;
    if (tetmesh_beam(&t, 1, 0.1, 0.1, 10 * k, k, k, TETMESH_SPLIT5) != TETMESH_OK) return -1;
    x = alloc_reals(3 * t.node_count);
    for (i = 0; i < 3 * t.node_count; i++) x[i] = (frm_real)t.nodes[i];
    for (i = 0; i < t.node_count; i++)
        if (fabs(t.nodes[3 * i]) < 1e-12) x[3 * i] = 0;
    err = frm_sampling_tets(s, x, t.node_count, t.tets, t.tet_count, 1, NULL, NULL);
    free(x);
    tetmesh_free(&t);
    if (err) return err;
    frm_sampling_apply(s, &d);
    d.material.young_modulus = (frm_real)1e6;
    d.material.poisson_ratio = (frm_real)0.3;
    d.material.density = 1000;
    d.gravity[2] = 0;
    d.rotation_divergence = (frm_real)gamma;
    d.parallel_min_pairs = 1 << 30;
    err = frm_model_create(&d, m);
    if (err) return err;
    for (i = 0; i < s->frame_count; i++)
        if (s->frame_positions[3 * i] == 0) frm_model_fix_frame(*m, i);
    return 0;
}

/* Issue 16: the public view and pass functions are a backend of their own. A serial loop
   in this test over frm_model_view's arrays (frm_pass1_deform, the kernels' law, the
   stabilisation, frm_pass1_force_pairs, frm_pass2_gather; frm_pass1_apply_dF, frm_sample_dP,
   frm_pass1_apply_pairs, frm_pass2_gather and _rotational) gives the model's own forces and
   K v bit for bit (the same expressions in the same order: exact equality is the claim),
   on the tetrahedral R3 beam one cell across (frames with unseen rotations: both kinds of
   stabilisation pairs) in a deformed state, the default law. */
static void test_view_passes(void)
{
    frm_sampling s;
    frm_model *m = NULL;
    frm_view w;
    const frm_real *f;
    frm_real g[3] = {0, 3, -200}, *buf, *v, *kv, *mine;
    int i, k, n, same_f = 1, same_kv = 1;
    REQUIRE(tet_beam(&s, &m, 1, 4) == 0);
    frm_sampling_free(&s);
    CHECK_INT(0, frm_model_set_stiffness_mode(m, FRM_STIFFNESS_PAIRS));
    CHECK_INT(FRM_ERR_ARG, frm_model_view(m, NULL));
    CHECK_INT(0, frm_model_view(m, &w));
    CHECK_INT(frm_model_frame_count(m), w.frame_count);
    CHECK_INT(frm_model_pair_count(m), w.pair_count);
    CHECK(frm_model_stabilized_frames(m) > 0);
    frm_model_set_gravity(m, g);
    for (i = 0; i < 3; i++) CHECK_INT(0, frm_model_step(m));
    n = 6 * w.frame_count;
    buf = alloc_reals(3 * n);
    v = buf, kv = buf + n, mine = buf + 2 * n;
    CHECK_INT(0, frm_model_forces(m, &f));
    for (i = 0; i < w.sample_count; i++) { /* pass 1 of the force, as frames_cuda.cu runs it */
        frm_real H[9], F[9], S[6], P[9], cache[FRM_LAW_CACHE], psi, D = 0;
        const frm_real *prm = w.s_law_params + FRM_LAW_PARAMS * (size_t)i;
        double e = 0;
        frm_pass1_deform(&w, i, H, F, NULL);
        REQUIRE(frm_material_stress(w.s_law[i], prm[0], prm[1], H, S, &psi, cache) == 0);
        frm_first_piola(F, S, P);
        if (w.s_stab[i]) e += frm_pass1_stab_force(&w, i, H, F, P, 0, &D);
        frm_pass1_force_pairs(&w, i, H, F, P, D, 0, &e);
    }
    for (i = 0; i < w.frame_count; i++) frm_pass2_gather(&w, i, w.p_out, mine, NULL);
    for (k = 0; k < n; k++) same_f &= mine[k] == f[k];
    CHECK(same_f);
    for (k = 0; k < n; k++) v[k] = (frm_real)(1e-3 * ((k * 37) % 11 - 5));
    CHECK_INT(0, frm_model_prepare_stiffness(m));
    CHECK_INT(0, frm_model_apply_stiffness(m, v, kv, 1));
    for (i = 0; i < w.sample_count; i++) {
        frm_real dF[9], dP[9];
        const frm_real *prm = w.s_law_params + FRM_LAW_PARAMS * (size_t)i;
        frm_pass1_apply_dF(&w, i, v, dF);
        frm_sample_dP(w.s_law[i], prm[0], prm[1], w.lin_cache + (size_t)w.law_cache * i, w.lin_F + 9 * (size_t)i,
                      w.lin_S + 6 * (size_t)i, dF, dP);
        frm_pass1_apply_pairs(&w, i, v, dF, dP, 0);
    }
    for (i = 0; i < w.frame_count; i++) {
        frm_pass2_gather(&w, i, w.p_out, mine, NULL);
        frm_pass2_rotational(&w, i, v, mine);
    }
    for (k = 0; k < n; k++) same_kv &= mine[k] == kv[k];
    CHECK(same_kv);
    free(buf);
    frm_model_destroy(m);
}

/* Modes below `limit` Hz (not counting those at or below zero: none on a clamped beam)
   and, of those, the ones whose kinetic energy is mostly the frames' rotations. */
static void count_low(const double *freq, const double *rot, int n, double limit, int *low, int *rotational)
{
    int i;
    *low = *rotational = 0;
    for (i = 0; i < n && freq[i] < limit; i++) {
        (*low)++;
        if (i < 8 && rot[i] > 0.5) (*rotational)++;
    }
}

/* The R3 beam with tetrahedral frames, one sample per tetrahedron (REFERENCES R3, 3D:
   first bending 0.5091 Hz, twice on the square section; second bending 3.0531 Hz; first
   torsion 4.5101 Hz). The thesis's model (rotation_divergence = 0) has a mode at 0.39 Hz
   (one cell across) / 0.42 Hz (two) below the first bending mode and one at 2.3 / 2.5 Hz
   below the second, in which the frames turn about the beam's axis while the material
   hardly moves (more than 90 % of their kinetic energy is the frames' rotation). The
   divergence term removes them: on two cells across no mode lies in (0, 0.95 x 0.5091 Hz),
   the lowest two are the bending pair within 3 % of 0.5091 Hz (the discretisation is soft:
   its static sag is +4.6 % of beam theory, which alone puts the frequency 2.2 % low), and no
   mode below 0.95 x the second bending frequency is mostly rotation. One cell across
   (quick builds) the bending pair itself sits 12 % low (sag +29 %), so there the check is
   that the modes below 0.95 x 3.0531 Hz are the two bending pairs, none rotational. */
static void test_tet_beam_modes(void)
{
    int k, k0 = TEST_IS_QUICK ? 1 : 2;
    for (k = 1; k <= 2; k++) {
        int pass;
        if (k != k0 && !(k == 1 && !TEST_IS_QUICK)) continue;
        for (pass = 0; pass < 2; pass++) { /* 0: the thesis's rotations (the defect), 1: default */
            frm_sampling s;
            frm_model *m;
            frm_desc probe = frm_model_default_desc();
            double *freq, rot[8];
            int n, i, low1, rot1, low2, rot2;
            if (pass == 0 && k == 2) continue; /* the defect is shown once, on the small beam */
            REQUIRE(tet_beam(&s, &m, k, pass == 0 ? 0 : (double)probe.rotation_divergence) == FRM_OK);
            freq = (double *)calloc((size_t)6 * s.frame_count, sizeof(double));
            n = model_modes(m, freq, rot, 8);
            REQUIRE(n > 8);
            printf("    tet frames, R3 beam %d x %d x %d cells (%d DoF), rotation_divergence %g: lowest modes (Hz, rotation "
                   "share of kinetic energy):\n     ",
                   10 * k, k, k, n, pass == 0 ? 0.0 : (double)probe.rotation_divergence);
            for (i = 0; i < 8; i++) printf(" %.4f (%.2f)", freq[i], rot[i]);
            printf("\n");
            CHECK(freq[0] > 0);
            count_low(freq, rot, n, 0.95 * 0.5091, &low1, &rot1);
            count_low(freq, rot, n, 0.95 * 3.0531, &low2, &rot2);
            if (pass == 0) { /* the thesis's model shows the defect the test is for */
                CHECK(rot1 >= 1);
                CHECK(rot2 >= 2);
            } else if (k == 2) {
                CHECK_INT(0, low1);
                CHECK_INT(0, rot2);
                CHECK_INT(2, low2);
                CHECK_REL(0.5091, freq[0], 0.03);
                CHECK_REL(0.5091, freq[1], 0.03);
            } else {
                CHECK_INT(0, rot2);
                CHECK_INT(4, low2);
                CHECK(rot[0] < 0.1 && rot[1] < 0.1);
            }
            free(freq);
            frm_model_destroy(m);
            frm_sampling_free(&s);
        }
    }
}

/* A hexahedral beam [0, L] x [-W/2, W/2]^2 of nx x n x n cells, 2^3 sub-cell samples each
   (frames at the nodes), clamped at x = 0; gamma < 0: the default rotation_divergence. */
static int hex_beam(frm_sampling *s, frm_model **m, double L, double W, int nx, int n, double E, double rho, double gamma,
                    int gravity)
{
    hexmesh h;
    frm_desc d = frm_model_default_desc();
    double lo[3], hi[3];
    frm_real *x;
    int i, err;
    lo[0] = 0;
    lo[1] = lo[2] = -W / 2;
    hi[0] = L;
    hi[1] = hi[2] = W / 2;
    if (hexmesh_grid(&h, lo, hi, nx, n, n) != TETMESH_OK) return -1;
    x = alloc_reals(3 * h.node_count);
    for (i = 0; i < 3 * h.node_count; i++) x[i] = (frm_real)h.nodes[i];
    for (i = 0; i < h.node_count; i++)
        if (h.nodes[3 * i] == 0) x[3 * i] = 0;
    err = frm_sampling_hexes(s, x, h.node_count, h.hexes, h.hex_count, 2, FRM_QUADRATURE_SUBCELL, NULL);
    free(x);
    hexmesh_free(&h);
    if (err) return err;
    frm_sampling_apply(s, &d);
    d.material.young_modulus = (frm_real)E;
    d.material.poisson_ratio = (frm_real)0.3;
    d.material.density = (frm_real)rho;
    if (!gravity) d.gravity[2] = 0;
    if (gamma >= 0) d.rotation_divergence = (frm_real)gamma;
    d.parallel_min_pairs = 1 << 30;
    err = frm_model_create(&d, m);
    if (err) return err;
    for (i = 0; i < s->frame_count; i++)
        if (s->frame_positions[3 * i] == 0) frm_model_fix_frame(*m, i);
    return 0;
}

/* Hexahedral frames one cell across: on a tensor-product grid a layer of frames normal to
   an axis, turning about that axis, moves no material at all (the bilinear face
   interpolation reproduces the in-plane coordinates): zero-energy modes of the
   linearisation, and static solves stalled. Their rotation field has a divergence, which
   the divergence term holds. The R3 beam of 10 x 1 x 1 cells: the thesis's model
   (rotation_divergence = 0) has generalized eigenvalues of (K, M) at zero (below 1e-6 of
   the first bending mode's; float's round-off of K puts them within 0.04 Hz); with the default none lies below 0.8 x 0.5091 Hz (the bending
   pair itself is 8 % low one cell across: the frames' rotations make one cell soft, see
   the R1 test below). */
static void test_hex_beam_modes(void)
{
    int pass;
    for (pass = 0; pass < 2; pass++) {
        frm_sampling s;
        frm_model *m;
        double *freq, rot[6];
        int n, i;
        REQUIRE(hex_beam(&s, &m, 1, 0.1, 10, 1, 1e6, 1000, pass == 0 ? 0 : -1, 0) == FRM_OK);
        freq = (double *)calloc((size_t)6 * s.frame_count, sizeof(double));
        n = model_modes(m, freq, rot, 6);
        REQUIRE(n > 6);
        printf("    hex frames, R3 beam 10 x 1 x 1 cells (%d DoF), %s: lowest modes (Hz, rotation share):\n     ", n,
               pass == 0 ? "rotation_divergence 0" : "default");
        for (i = 0; i < 6; i++) printf(" %.4f (%.2f)", freq[i], rot[i]);
        printf("; highest %.1f\n", freq[n - 1]);
        if (pass == 0) CHECK(fabs(freq[0]) < (IS_FLOAT ? 0.2 : 1e-3) * 0.5091); /* float: K's round-off, 0.04 Hz */
        else CHECK(freq[0] > 0.8 * 0.5091);
        free(freq);
        frm_model_destroy(m);
        frm_sampling_free(&s);
    }
}

/* The tip of the R1 beam (16 x 0.5 x 0.5 m steel, own weight) with hexahedral frames. */
static double hex_r1_tip(int nx, int n, int *err, int *newton)
{
    frm_sampling s;
    frm_model *m;
    double L = 16, W = 0.5, tip = 0;
    int i, c = 0;
    *newton = 0;
    *err = hex_beam(&s, &m, L, W, nx, n, 200e9, 31200 / (L * W * W), -1, 1);
    if (*err) return 0;
    *err = frm_model_set_solver(m, (frm_real)(IS_FLOAT ? 1e-5 : 1e-10), 20000, (frm_real)(IS_FLOAT ? 1e-3 : 1e-6), 30);
    if (!*err) *err = frm_model_solve_static(m);
    *newton = frm_model_last_stats(m)->newton_iterations;
    for (i = 0; i < s.frame_count; i++)
        if (fabs((double)s.frame_positions[3 * i] - L) < 1e-9 * L) {
            tip -= (double)frm_model_positions(m)[3 * i + 2] - (double)s.frame_positions[3 * i + 2];
            c++;
        }
    frm_model_destroy(m);
    frm_sampling_free(&s);
    return tip / c;
}

/* R1 with hexahedral frames one cell across (32 x 1 x 1 cells of 0.5 m): the static solve
   used to stall (FRM_ERR_STALLED); it converges in a few Newton iterations and lands 20 %
   above the 3D reference 0.150169 m (measured +20.4 %), the discretisation's own error:
   one cell across the frames' rotations make a cell soft in bending, as tetrahedral frames
   one cell across (+29 % on R3), and two cells across (64 x 2 x 2, full builds) it is +4.1 %
   (the thesis's 24 x 4 x 4: +0.2 %, tests/test_frames.c). Checked: converged, within
   [0, +25 %] one cell across, [0, +6 %] at two. */
static void test_hex_one_cell_r1(void)
{
    double ref = 0.150169, tip;
    int err, newton;
    tip = hex_r1_tip(32, 1, &err, &newton);
    printf("    R1 hex frames 33 x 2 x 2: %s, tip %.6f m (3D %.6f: %+.2f %%), %d Newton\n", frm_error_string(err), tip, ref,
           100 * (tip / ref - 1), newton);
    CHECK_INT(FRM_OK, err);
    CHECK(newton <= 10);
    CHECK(tip > ref && tip < 1.25 * ref);
    if (!TEST_IS_QUICK) {
        tip = hex_r1_tip(64, 2, &err, &newton);
        printf("    R1 hex frames 65 x 3 x 3: %s, tip %.6f m (%+.2f %%), %d Newton\n", frm_error_string(err), tip,
               100 * (tip / ref - 1), newton);
        CHECK_INT(FRM_OK, err);
        CHECK(tip > ref && tip < 1.06 * ref);
    }
}

/* R2, the soft cantilever 16 x 1 x 1 m (E = 40 kPa, 5 kg), with hexahedral frames one and
   two cells across: the static solve stalled at every resolution; now it converges, below
   linear theory's 7.53 m (large deformation), the tip falling under refinement towards the
   tetrahedral frames' limit of about 6.54 m (tests/test_frames.c). Measured 7.203, 6.656 m. */
static void test_hex_soft_cantilever_r2(void)
{
    int r, count = TEST_IS_QUICK ? 1 : 2;
    double tip[2];
    for (r = 0; r < count; r++) {
        frm_sampling s;
        frm_model *m;
        double L = 16, t = 0;
        int i, c = 0, err;
        REQUIRE(hex_beam(&s, &m, L, 1, 16 * (r + 1), r + 1, 40e3, 5.0 / 16, -1, 1) == FRM_OK);
        REQUIRE(frm_model_set_solver(m, (frm_real)(IS_FLOAT ? 1e-5 : 1e-8), 5000, (frm_real)(IS_FLOAT ? 1e-4 : 1e-6), 100) ==
                FRM_OK);
        err = frm_model_solve_static(m);
        for (i = 0; i < s.frame_count; i++)
            if (fabs((double)s.frame_positions[3 * i] - L) < 1e-9 * L) {
                t -= (double)frm_model_positions(m)[3 * i + 2] - (double)s.frame_positions[3 * i + 2];
                c++;
            }
        tip[r] = t / c;
        printf("    R2 hex frames %d x %d x %d: %s, tip %.4f m, %d Newton, %d CG\n", 16 * (r + 1) + 1, r + 2, r + 2,
               frm_error_string(err), tip[r], frm_model_last_stats(m)->newton_iterations,
               frm_model_last_stats(m)->cg_iterations);
        CHECK_INT(FRM_OK, err);
        CHECK(tip[r] > 6 && tip[r] < 7.53);
        frm_model_destroy(m);
        frm_sampling_free(&s);
    }
    if (count == 2) CHECK(tip[1] < tip[0]);
}

/* ---- issue 20: every law through the path the model uses ------------------------- */

/* A user law that re-implements the compressible Neo-Hookean law in invariants:
   W = mu/2 (I1 - 3) - mu ln J + lambda/2 ln^2 J, w_1 = mu/2, w_J = (lambda ln J - mu)/J,
   w_JJ = (mu + lambda (1 - ln J))/J^2, the others 0. user = {mu, lambda}. */
static void user_nh_energy(frm_law_points *p, void *user)
{
    const double *c = (const double *)user;
    int k;
    for (k = 0; k < p->count; k++) {
        double L = log((double)p->J[k]);
        p->w[k] = (frm_real)(0.5 * c[0] * ((double)p->I1[k] - 3) - c[0] * L + 0.5 * c[1] * L * L);
    }
}

static void user_nh_first(frm_law_points *p, void *user)
{
    const double *c = (const double *)user;
    int k;
    for (k = 0; k < p->count; k++) {
        double J = (double)p->J[k], L = log(J);
        p->w_1[k] = (frm_real)(0.5 * c[0]);
        p->w_2[k] = 0;
        p->w_J[k] = (frm_real)((c[1] * L - c[0]) / J);
    }
}

static void user_nh_second(frm_law_points *p, void *user)
{
    const double *c = (const double *)user;
    int k;
    for (k = 0; k < p->count; k++) {
        double J = (double)p->J[k], L = log(J);
        p->w_11[k] = p->w_12[k] = p->w_1J[k] = p->w_22[k] = p->w_2J[k] = 0;
        p->w_JJ[k] = (frm_real)((c[0] + c[1] * (1 - L)) / (J * J));
    }
}

#define LAW_E 1e5
#define LAW_NU 0.3
static double user_nh_constants[2] = {LAW_E / (2 * (1 + LAW_NU)), LAW_E * LAW_NU / ((1 + LAW_NU) * (1 - 2 * LAW_NU))};

/* The material each law is tested with: E = 1e5 Pa, nu = 0.3 (SVK, Neo-Hookean, the user
   Neo-Hookean); Mooney-Rivlin c1 = 1e4, c2 = 5e3, kappa = 2e5 Pa. */
static frm_material law_material(int law)
{
    frm_material mat = frm_model_default_desc().material;
    mat.law = (frm_law)law;
    mat.young_modulus = (frm_real)LAW_E;
    mat.poisson_ratio = (frm_real)LAW_NU;
    mat.c1 = (frm_real)1e4;
    mat.c2 = (frm_real)5e3;
    mat.bulk_modulus = (frm_real)2e5;
    if (law == FRM_LAW_USER) {
        mat.user.energy = user_nh_energy;
        mat.user.first = user_nh_first;
        mat.user.second = user_nh_second;
        mat.user.user = user_nh_constants;
    }
    return mat;
}

static double law_rand(unsigned *state)
{
    *state = *state * 1664525u + 1013904223u;
    return (double)(*state >> 8) / 16777216.0 * 2 - 1;
}

static void law_first_piola(const frm_real H[9], const frm_real S[6], double P[9])
{
    frm_real F[9], Pf[9];
    int k;
    for (k = 0; k < 9; k++) F[k] = H[k] + (k % 4 == 0 ? 1 : 0);
    frm_first_piola(F, S, Pf);
    for (k = 0; k < 9; k++) P[k] = (double)Pf[k];
}

/* Per law: force = -gradient (P : dH equals the derivative of the law table's energy),
   differential = derivative (dS and dP of the model's path equal the derivative of its
   stress), the stress pass's energy equals the table's. All through frm__law_stress /
   frm__law_dstress / frm__law_dP, the functions the model's loops call, so a law whose
   fast_path flag routes it to another law's kernel fails here. */
static void test_law_derivatives(void)
{
    double h = IS_FLOAT ? 1e-3 : 1e-6, tol = IS_FLOAT ? 2e-3 : 1e-6;
    int law, trial, k;
    unsigned seed = 12345u;
    for (law = 0; law < FRM_LAW_COUNT; law++) {
        frm_material mat = law_material(law);
        frm_real prm[FRM_LAW_PARAMS], mu;
        const frm_user_law *user = law == FRM_LAW_USER ? &mat.user : NULL;
        const frm__law_ops *ops = &frm__laws[law];
        double worst_f = 0, worst_d = 0;
        frm__law_params(&mat, prm, &mu);
        for (trial = 0; trial < 6; trial++) {
            frm_real H[9], dH[9], Hp[9], Hm[9], S[6], Sp[6], Sm[6], dS[6], dE[6], F[9], dP[9], cache[FRM__LAW_CACHE_MAX];
            frm_real cp[FRM__LAW_CACHE_MAX], psi, psi_t, psp, psm;
            double P[9], Pp[9], Pm[9], an = 0, fd, pn = 0, dn = 0, sn = 0, err_s = 0, err_p = 0, amp = trial < 3 ? 0.1 : 0.3;
            for (k = 0; k < 9; k++) {
                H[k] = (frm_real)(amp * law_rand(&seed));
                dH[k] = (frm_real)law_rand(&seed);
            }
            for (k = 0; k < 9; k++) {
                Hp[k] = (frm_real)((double)H[k] + h * (double)dH[k]);
                Hm[k] = (frm_real)((double)H[k] - h * (double)dH[k]);
                F[k] = H[k] + (k % 4 == 0 ? 1 : 0);
            }
            REQUIRE(frm__law_stress(law, prm, user, H, S, &psi, cache) == 0);
            REQUIRE(ops->energy(prm, user, H, &psi_t) == 0);
            CHECK_NEAR(psi_t, psi, tol * (fabs((double)psi_t) + 1e-3 * LAW_E));
            law_first_piola(H, S, P);
            REQUIRE(ops->energy(prm, user, Hp, &psp) == 0 && ops->energy(prm, user, Hm, &psm) == 0);
            fd = ((double)psp - (double)psm) / (2 * h);
            for (k = 0; k < 9; k++) {
                an += P[k] * (double)dH[k];
                pn += P[k] * P[k];
                dn += (double)dH[k] * (double)dH[k];
            }
            if (fabs(fd - an) / sqrt(pn * dn) > worst_f) worst_f = fabs(fd - an) / sqrt(pn * dn);
            /* differential: dS at dE = sym(F^T dH), dP = dH S + F dS */
            {
                frm_real t[9];
                int r, c;
                for (r = 0; r < 3; r++)
                    for (c = 0; c < 3; c++) t[3 * r + c] = F[r] * dH[c] + F[3 + r] * dH[3 + c] + F[6 + r] * dH[6 + c];
                dE[0] = t[0], dE[1] = t[4], dE[2] = t[8];
                dE[3] = (frm_real)0.5 * (t[5] + t[7]), dE[4] = (frm_real)0.5 * (t[2] + t[6]), dE[5] = (frm_real)0.5 * (t[1] + t[3]);
            }
            frm__law_dstress(law, prm, user, cache, dE, dS);
            frm__law_dP(law, prm, user, cache, F, S, dH, dP);
            REQUIRE(frm__law_stress(law, prm, user, Hp, Sp, &psp, cp) == 0);
            REQUIRE(frm__law_stress(law, prm, user, Hm, Sm, &psm, cp) == 0);
            law_first_piola(Hp, Sp, Pp);
            law_first_piola(Hm, Sm, Pm);
            for (k = 0; k < 6; k++) sn += (double)dS[k] * (double)dS[k];
            for (k = 0; k < 6; k++) {
                double e = fabs(((double)Sp[k] - (double)Sm[k]) / (2 * h) - (double)dS[k]) / sqrt(sn);
                if (e > err_s) err_s = e;
            }
            sn = 0;
            for (k = 0; k < 9; k++) sn += (double)dP[k] * (double)dP[k];
            for (k = 0; k < 9; k++) {
                double e = fabs((Pp[k] - Pm[k]) / (2 * h) - (double)dP[k]) / sqrt(sn);
                if (e > err_p) err_p = e;
            }
            if (err_s > worst_d) worst_d = err_s;
            if (err_p > worst_d) worst_d = err_p;
        }
        printf("    %-20s force vs -grad W %.1e, differential vs d(force) %.1e\n", ops->name, worst_f, worst_d);
        CHECK(worst_f < tol);
        CHECK(worst_d < tol);
    }
}

/* The user law that re-implements Neo-Hookean gives FRM_LAW_NEO_HOOKEAN's stress, energy and
   differential (to round-off: the kernel and the invariant path regroup the terms). */
static void test_law_user_matches_neo_hookean(void)
{
    frm_material nh = law_material(FRM_LAW_NEO_HOOKEAN), us = law_material(FRM_LAW_USER);
    frm_real pn[FRM_LAW_PARAMS], pu[FRM_LAW_PARAMS], mu;
    double tol = IS_FLOAT ? 1e-4 : 1e-10, worst = 0;
    unsigned seed = 777u;
    int trial, k;
    frm__law_params(&nh, pn, &mu);
    frm__law_params(&us, pu, &mu);
    CHECK(pn[0] == pu[0] && pn[1] == pu[1]);
    for (trial = 0; trial < 8; trial++) {
        frm_real H[9], dE[6], Sn[6], Su[6], dSn[6], dSu[6], cn[FRM__LAW_CACHE_MAX], cu[FRM__LAW_CACHE_MAX], wn, wu;
        double scale = 0;
        for (k = 0; k < 9; k++) H[k] = (frm_real)(0.2 * law_rand(&seed));
        for (k = 0; k < 6; k++) dE[k] = (frm_real)law_rand(&seed);
        REQUIRE(frm__law_stress(FRM_LAW_NEO_HOOKEAN, pn, NULL, H, Sn, &wn, cn) == 0);
        REQUIRE(frm__law_stress(FRM_LAW_USER, pu, &us.user, H, Su, &wu, cu) == 0);
        frm__law_dstress(FRM_LAW_NEO_HOOKEAN, pn, NULL, cn, dE, dSn);
        frm__law_dstress(FRM_LAW_USER, pu, &us.user, cu, dE, dSu);
        for (k = 0; k < 6; k++) scale = fmax(scale, fabs((double)Sn[k]));
        for (k = 0; k < 6; k++) worst = fmax(worst, fabs((double)Sn[k] - (double)Su[k]) / scale);
        scale = 0;
        for (k = 0; k < 6; k++) scale = fmax(scale, fabs((double)dSn[k]));
        for (k = 0; k < 6; k++) worst = fmax(worst, fabs((double)dSn[k] - (double)dSu[k]) / scale);
        worst = fmax(worst, fabs((double)wn - (double)wu) / fabs((double)wn));
    }
    printf("    user Neo-Hookean vs FRM_LAW_NEO_HOOKEAN: %.1e relative\n", worst);
    CHECK(worst < tol);
}

/* Uniaxial closed forms of the unit cube (REFERENCES R4, R5 and Mooney-Rivlin's), checked
   on the homogeneous state F = diag(t, t, s) at the law level: the law's lateral stress
   P_xx vanishes at the closed form's lateral stretch t and its P_zz equals the closed form.

   Mooney-Rivlin (derived here). W(l1, l2, l3) = c1 (I1 J^-2/3 - 3) + c2 (I2 J^-4/3 - 3)
   + kappa/2 (J - 1)^2 with I1 = sum l_i^2, I2 = sum_{i<j} l_i^2 l_j^2, J = l1 l2 l3. With
   dI1/dl_i = 2 l_i, dI2/dl_i = 2 l_i (I1 - l_i^2), dJ/dl_i = J / l_i, the principal first
   Piola-Kirchhoff stress is
       P_i = dW/dl_i = 2 l_i w_1 + 2 l_i (I1 - l_i^2) w_2 + J/l_i w_J,
       w_1 = c1 J^-2/3, w_2 = c2 J^-4/3, w_J = -2/3 c1 I1 J^-5/3 - 4/3 c2 I2 J^-7/3 + kappa (J - 1).
   For l = (t, t, s): J = s t^2, I1 = 2 t^2 + s^2, I2 = t^4 + 2 s^2 t^2, I1 - t^2 = t^2 + s^2,
   I1 - s^2 = 2 t^2. Free lateral faces: P_x(t) = 0, solved for t by a scalar Newton from
   t = 1 (the derivative by central differences); then P_zz = P_z(t). At s = 1, t = 1 and
   P = 0 (2 c1 + 4 c2 + w_J = 0 at rest). */
static void mr_principal(double c1, double c2, double kappa, double t, double s, double *Px, double *Pz)
{
    double J = s * t * t, I1 = 2 * t * t + s * s, I2 = t * t * t * t + 2 * s * s * t * t;
    double a = pow(J, -2.0 / 3.0), b = a * a;
    double w1 = c1 * a, w2 = c2 * b, wJ = (-2.0 / 3.0 * c1 * I1 * a - 4.0 / 3.0 * c2 * I2 * b) / J + kappa * (J - 1);
    *Px = 2 * t * w1 + 2 * t * (t * t + s * s) * w2 + J / t * wJ;
    *Pz = 2 * s * w1 + 2 * s * (2 * t * t) * w2 + J / s * wJ;
}

static double closed_form_uniaxial(int law, double s, double mu, double lambda, double c1, double c2, double kappa,
                                   double *lateral)
{
    double t = 1, Px, Pz;
    int it;
    if (law == FRM_LAW_SVK) { /* S_xx = 0: E_xx = -lambda E_zz / (2 (lambda + mu)) */
        double Ezz = 0.5 * (s * s - 1), Exx = -lambda * Ezz / (2 * (lambda + mu));
        *lateral = sqrt(1 + 2 * Exx);
        return mu * (3 * lambda + 2 * mu) / (2 * (lambda + mu)) * (s * s * s - s); /* R4 */
    }
    for (it = 0; it < 60; it++) {
        double f, fp, fm, d = 1e-7, dummy;
        if (law == FRM_LAW_MOONEY_RIVLIN) {
            mr_principal(c1, c2, kappa, t, s, &f, &dummy);
            mr_principal(c1, c2, kappa, t + d, s, &fp, &dummy);
            mr_principal(c1, c2, kappa, t - d, s, &fm, &dummy);
        } else { /* R5: P_xx = mu (t - 1/t) + lambda ln(s t^2) / t */
            f = mu * (t - 1 / t) + lambda * log(s * t * t) / t;
            fp = mu * (t + d - 1 / (t + d)) + lambda * log(s * (t + d) * (t + d)) / (t + d);
            fm = mu * (t - d - 1 / (t - d)) + lambda * log(s * (t - d) * (t - d)) / (t - d);
        }
        t -= f / ((fp - fm) / (2 * d));
    }
    *lateral = t;
    if (law == FRM_LAW_MOONEY_RIVLIN) {
        mr_principal(c1, c2, kappa, t, s, &Px, &Pz);
        return Pz;
    }
    return mu * (s - 1 / s) + lambda * log(s * t * t) / s; /* R5 */
}

static void test_law_uniaxial_closed_forms(void)
{
    static const int laws[] = {FRM_LAW_SVK, FRM_LAW_NEO_HOOKEAN, FRM_LAW_MOONEY_RIVLIN, FRM_LAW_USER};
    double tol = IS_FLOAT ? 1e-4 : 1e-10;
    int li, k;
    for (li = 0; li < 4; li++) {
        int law = laws[li];
        frm_material mat = law_material(law);
        frm_real prm[FRM_LAW_PARAMS], mu;
        double worst = 0, s;
        frm__law_params(&mat, prm, &mu);
        for (s = 0.5; s <= 1.5001; s += 0.125) {
            double t, Pzz, P[9], mu_d = (double)prm[0], la = (double)prm[1];
            frm_real H[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, S[6], psi, cache[FRM__LAW_CACHE_MAX];
            /* the user law re-implements Neo-Hookean: R5 */
            Pzz = closed_form_uniaxial(law == FRM_LAW_USER ? FRM_LAW_NEO_HOOKEAN : law, s, mu_d, la, (double)mat.c1,
                                       (double)mat.c2, (double)mat.bulk_modulus, &t);
            H[0] = H[4] = (frm_real)(t - 1);
            H[8] = (frm_real)(s - 1);
            REQUIRE(frm__law_stress(law, prm, law == FRM_LAW_USER ? &mat.user : NULL, H, S, &psi, cache) == 0);
            law_first_piola(H, S, P);
            {
                double scale = fabs(Pzz) + 1e-2 * (double)mu;
                double e = fmax(fabs(P[8] - Pzz), fmax(fabs(P[0]), fabs(P[4]))) / scale;
                for (k = 0; k < 9; k++)
                    if (k % 4 != 0) e = fmax(e, fabs(P[k]) / scale);
                if (e > worst) worst = e;
            }
        }
        printf("    %-20s uniaxial P_zz and P_xx = 0 vs the closed form: %.1e relative\n", frm__laws[law].name, worst);
        CHECK(worst < tol);
    }
}

/* The model's forces and K v for every law on one hexahedral cell (2^3 Gauss samples, no
   stabilisation, coupling or gravity, so the energy is sum_s v_s W(F_s)): force = -gradient of the
   energy summed from the law table's `energy` (independent of the fast path), and
   K v = -(derivative of the model's force along v). The frames translate and turn. */
static void test_law_model_path(void)
{
    frm_real nodes[24];
    int hex[8], law, i, k;
    double h = IS_FLOAT ? 1e-3 : 1e-6, tol = IS_FLOAT ? 5e-3 : 1e-6;
    for (k = 0; k < 8; k++) {
        hex[k] = k;
        nodes[3 * k] = (frm_real)(k & 1);
        nodes[3 * k + 1] = (frm_real)((k >> 1) & 1);
        nodes[3 * k + 2] = (frm_real)((k >> 2) & 1);
    }
    for (law = 0; law < FRM_LAW_COUNT; law++) {
        frm_sampling s;
        frm_desc d;
        frm_model *m = NULL;
        frm_real pos[24], quat[32], pos0[24], v[48], Kv[48], fp[48], fm[48];
        const frm_real *f;
        frm_real prm[FRM_LAW_PARAMS], mu;
        frm_material mat = law_material(law);
        const frm_user_law *user = law == FRM_LAW_USER ? &mat.user : NULL;
        double worst_f = 0, worst_k = 0, fn = 0, kn = 0;
        unsigned seed = 99u;
        int a;
        REQUIRE(frm_sampling_hexes(&s, nodes, 8, hex, 1, 2, FRM_QUADRATURE_GAUSS, NULL) == FRM_OK);
        d = frm_model_default_desc();
        frm_sampling_apply(&s, &d);
        d.material = mat;
        d.rotation_stabilization = 0;
        d.rotation_divergence = 0;
        d.gravity[0] = d.gravity[1] = d.gravity[2] = 0; /* K holds gravity's stiffness too */
        REQUIRE(frm_model_create(&d, &m) == FRM_OK);
        frm__law_params(&mat, prm, &mu);
        for (i = 0; i < 8; i++) {
            double th[3], n;
            for (k = 0; k < 3; k++) pos0[3 * i + k] = (frm_real)((double)nodes[3 * i + k] + 0.08 * law_rand(&seed));
            for (k = 0; k < 3; k++) th[k] = 0.1 * law_rand(&seed);
            n = sqrt(th[0] * th[0] + th[1] * th[1] + th[2] * th[2]);
            for (k = 0; k < 3; k++) quat[4 * i + k] = (frm_real)(sin(0.5 * n) * th[k] / n);
            quat[4 * i + 3] = (frm_real)cos(0.5 * n);
        }
        /* force = -dW/dx over the translations, W from the law table */
        REQUIRE(frm_model_set_poses(m, pos0, quat) == FRM_OK);
        REQUIRE(frm_model_forces(m, &f) == FRM_OK);
        for (i = 0; i < 48; i++) fn = fmax(fn, fabs((double)f[i]));
        memcpy(fp, f, sizeof fp);
        for (i = 0; i < 8; i++)
            for (a = 0; a < 3; a++) {
                double W[2];
                int side;
                for (side = 0; side < 2; side++) {
                    const frm_real *F;
                    int smp;
                    memcpy(pos, pos0, sizeof pos);
                    pos[3 * i + a] = (frm_real)((double)pos0[3 * i + a] + (side ? -h : h));
                    REQUIRE(frm_model_set_poses(m, pos, quat) == FRM_OK);
                    F = frm_model_deformation_gradients(m);
                    W[side] = 0;
                    for (smp = 0; smp < s.sample_count; smp++) {
                        frm_real H[9], psi;
                        for (k = 0; k < 9; k++) H[k] = F[9 * smp + k] - (k % 4 == 0 ? 1 : 0);
                        REQUIRE(frm__laws[law].energy(prm, user, H, &psi) == 0);
                        W[side] += (double)s.sample_volumes[smp] * (double)psi;
                    }
                }
                worst_f = fmax(worst_f, fabs(-(W[0] - W[1]) / (2 * h) - (double)fp[6 * i + a]) / fn);
            }
        /* K v = -d(force)/d(state) along v (translations and rotations, world axes) */
        REQUIRE(frm_model_set_poses(m, pos0, quat) == FRM_OK);
        for (i = 0; i < 48; i++) v[i] = (frm_real)law_rand(&seed);
        REQUIRE(frm_model_prepare_stiffness(m) == FRM_OK);
        REQUIRE(frm_model_apply_stiffness(m, v, Kv, 0) == FRM_OK);
        {
            int side;
            for (side = 0; side < 2; side++) {
                frm_real q[32];
                double e = side ? -h : h;
                for (i = 0; i < 8; i++) {
                    frm_real th[3];
                    for (k = 0; k < 3; k++) {
                        pos[3 * i + k] = (frm_real)((double)pos0[3 * i + k] + e * (double)v[6 * i + k]);
                        th[k] = (frm_real)(e * (double)v[6 * i + 3 + k]);
                    }
                    memcpy(q + 4 * i, quat + 4 * i, 4 * sizeof(frm_real));
                    frm_quat_integrate(q + 4 * i, th);
                }
                REQUIRE(frm_model_set_poses(m, pos, q) == FRM_OK);
                REQUIRE(frm_model_forces(m, &f) == FRM_OK);
                memcpy(side ? fm : fp, f, sizeof fp);
            }
        }
        for (i = 0; i < 48; i++) kn = fmax(kn, fabs((double)Kv[i]));
        for (i = 0; i < 48; i++) worst_k = fmax(worst_k, fabs(-((double)fp[i] - (double)fm[i]) / (2 * h) - (double)Kv[i]) / kn);
        printf("    %-20s model force vs -grad W %.1e, K v vs -d(force) %.1e\n", frm__laws[law].name, worst_f, worst_k);
        CHECK(worst_f < tol);
        CHECK(worst_k < tol);
        frm_model_destroy(m);
        frm_sampling_free(&s);
    }
}

/* The law table and the new material fields are validated with the sentinel. */
static void test_law_validation(void)
{
    frm_real frames[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, samples[3] = {(frm_real)0.2, (frm_real)0.2, (frm_real)0.2};
    frm_sampling s;
    frm_desc d;
    frm_model *m = NULL;
    REQUIRE(frm_sampling_meshless(&s, frames, 4, samples, 1, 1, NULL, NULL) == FRM_OK);
    d = frm_model_default_desc();
    frm_sampling_apply(&s, &d);
    d.material.law = FRM_LAW_COUNT;
    CHECK_INT(FRM_ERR_MATERIAL, frm_model_create(&d, &m));
    d.material.law = FRM_LAW_USER; /* no callbacks */
    CHECK_INT(FRM_ERR_MATERIAL, frm_model_create(&d, &m));
    d.material = law_material(FRM_LAW_MOONEY_RIVLIN);
    d.material.bulk_modulus = 0;
    CHECK_INT(FRM_ERR_MATERIAL, frm_model_create(&d, &m));
    d.material = law_material(FRM_LAW_MOONEY_RIVLIN);
    d.material.c1 = d.material.c2 = 0;
    CHECK_INT(FRM_ERR_MATERIAL, frm_model_create(&d, &m));
    d.material = law_material(FRM_LAW_MOONEY_RIVLIN);
    d.material.young_modulus = -1; /* not read by Mooney-Rivlin */
    CHECK_INT(FRM_OK, frm_model_create(&d, &m));
    frm_model_destroy(m);
    frm_sampling_free(&s);
}

/* ---- issue 20: integrators and linear solvers chosen by enums with sentinels ------- */

/* integrator = FRM_IMPLICIT_EULER_LINEARIZED is bit for bit the older implicit_linearized
   = 1; the default integrator is the Newton implicit Euler; values at or past the
   sentinels are refused. */
static void test_integrator_choice(void)
{
    frm_real nodes[24];
    int hex[8], k, variant;
    frm_real state[3][8 * 13];
    frm_sampling s;
    for (k = 0; k < 8; k++) {
        hex[k] = k;
        nodes[3 * k] = (frm_real)(k & 1);
        nodes[3 * k + 1] = (frm_real)((k >> 1) & 1);
        nodes[3 * k + 2] = (frm_real)((k >> 2) & 1);
    }
    REQUIRE(frm_sampling_hexes(&s, nodes, 8, hex, 1, 2, FRM_QUADRATURE_GAUSS, NULL) == FRM_OK);
    for (variant = 0; variant < 3; variant++) { /* 0: implicit_linearized = 1, 1: integrator, 2: default */
        frm_desc d = frm_model_default_desc();
        frm_model *m = NULL;
        int step, i;
        frm_sampling_apply(&s, &d);
        d.material.young_modulus = (frm_real)1e5;
        if (variant == 0) d.implicit_linearized = 1;
        if (variant == 1) d.integrator = FRM_IMPLICIT_EULER_LINEARIZED;
        REQUIRE(frm_model_create(&d, &m) == FRM_OK);
        for (i = 0; i < 8; i++)
            if (i % 2 == 0) frm_model_fix_frame(m, i);
        for (step = 0; step < 5; step++) CHECK_INT(FRM_OK, frm_model_step(m));
        memcpy(state[variant], frm_model_positions(m), sizeof(frm_real) * 24);
        memcpy(state[variant] + 24, frm_model_orientations(m), sizeof(frm_real) * 32);
        memcpy(state[variant] + 56, frm_model_velocities(m), sizeof(frm_real) * 48);
        frm_model_destroy(m);
    }
    CHECK(memcmp(state[0], state[1], sizeof state[0]) == 0);
    CHECK(memcmp(state[0], state[2], sizeof state[0]) != 0);
    {
        frm_desc d = frm_model_default_desc();
        frm_model *m = NULL;
        frm_sampling_apply(&s, &d);
        d.integrator = FRM_INTEGRATOR_COUNT;
        CHECK_INT(FRM_ERR_SOLVER, frm_model_create(&d, &m));
        d.integrator = (frm_integrator)-1;
        CHECK_INT(FRM_ERR_SOLVER, frm_model_create(&d, &m));
        d.integrator = FRM_IMPLICIT_EULER;
        d.linear_solver = FRM_LINEAR_SOLVER_COUNT;
        CHECK_INT(FRM_ERR_SOLVER, frm_model_create(&d, &m));
        d.linear_solver = (frm_linear_solver)-2; /* below FRM_LINEAR_SOLVER_AUTO (-1) */
        CHECK_INT(FRM_ERR_SOLVER, frm_model_create(&d, &m));
        d.linear_solver = FRM_LINEAR_SOLVER_CG;
        CHECK_INT(FRM_OK, frm_model_create(&d, &m));
        CHECK_INT(FRM_LINEAR_SOLVER_CG, frm_model_linear_solver(m));
        frm_model_destroy(m);
        d.linear_solver = FRM_LINEAR_SOLVER_AUTO;
        CHECK_INT(FRM_OK, frm_model_create(&d, &m));
        CHECK_INT(FRM_LINEAR_SOLVER_CG, frm_model_linear_solver(m)); /* a 3D sampling: not a chain */
        frm_model_destroy(m);
    }
    frm_sampling_free(&s);
    /* the tables cover their enums (also a compile-time assert in frames.h) */
    CHECK_INT(FRM_INTEGRATOR_COUNT, (int)(sizeof frm__integrators / sizeof frm__integrators[0]));
    CHECK_INT(FRM_LAW_COUNT, (int)(sizeof frm__laws / sizeof frm__laws[0]));
    for (k = 0; k < FRM_INTEGRATOR_COUNT; k++) CHECK(frm__integrators[k].name && frm__integrators[k].step);
    for (k = 0; k < FRM_LAW_COUNT; k++)
        CHECK(frm__laws[k].name && frm__laws[k].energy && frm__laws[k].stress && frm__laws[k].differential &&
              frm__laws[k].cache_size <= FRM__LAW_CACHE_MAX);
}


/* ---- issue 19: point probes ---------------------------------------------------------- */

/* The body [0, 1] x [0, 0.5] x [0, 0.5] as a model of each kind: 0 tetrahedra (4 Gauss
   samples each), 1 hexahedra (8 sub-cell samples), 2 Shepard and 3 MLS meshless frames
   at the grid's nodes with samples at the cell centres; the probe description to match. */
static int probe_scene(int kind, frm_model **m, frm_sampling *s, frm_probe_desc *pd, int **elements)
{
    double lo[3] = {0, 0, 0}, hi[3] = {1, 0.5, 0.5};
    frm_desc d = frm_model_default_desc();
    frm_real *x;
    hexmesh h;
    int i, err, count;
    *pd = frm_probe_default_desc();
    *elements = NULL;
    if (kind == 0) {
        tetmesh t;
        if (tetmesh_box(&t, lo, hi, 3, 2, 2, TETMESH_SPLIT5) != TETMESH_OK) return -1;
        x = alloc_reals(3 * t.node_count);
        for (i = 0; i < 3 * t.node_count; i++) x[i] = (frm_real)t.nodes[i];
        err = frm_sampling_tets(s, x, t.node_count, t.tets, t.tet_count, 4, NULL, NULL);
        count = 4 * t.tet_count;
        *elements = (int *)malloc(sizeof(int) * (size_t)count);
        memcpy(*elements, t.tets, sizeof(int) * (size_t)count);
        pd->kind = FRM_PROBE_TETS;
        pd->element_count = t.tet_count;
        tetmesh_free(&t);
    } else {
        if (hexmesh_grid(&h, lo, hi, 3, 2, 2) != TETMESH_OK) return -1;
        x = alloc_reals(3 * h.node_count);
        for (i = 0; i < 3 * h.node_count; i++) x[i] = (frm_real)h.nodes[i];
        if (kind == 1) {
            err = frm_sampling_hexes(s, x, h.node_count, h.hexes, h.hex_count, 2, FRM_QUADRATURE_SUBCELL, NULL);
            *elements = (int *)malloc(sizeof(int) * 8 * (size_t)h.hex_count);
            memcpy(*elements, h.hexes, sizeof(int) * 8 * (size_t)h.hex_count);
            pd->kind = FRM_PROBE_HEXES;
            pd->element_count = h.hex_count;
        } else {
            frm_real *c = alloc_reals(3 * 8 * h.hex_count);
            int e, a, r, k = 0;
            for (e = 0; e < h.hex_count; e++) /* 8 points a cell, at the sub-cell centres */
                for (k = 0; k < 8; k++)
                    for (r = 0; r < 3; r++) {
                        double lo_c = h.nodes[3 * h.hexes[8 * e] + r], hi_c = h.nodes[3 * h.hexes[8 * e + 7] + r];
                        a = (k >> r) & 1;
                        c[3 * (8 * e + k) + r] = (frm_real)(lo_c + (hi_c - lo_c) * (a ? 0.75 : 0.25));
                    }
            pd->kind = FRM_PROBE_MESHLESS;
            if (kind == 3) {
                pd->shape.shape = FRM_SHAPE_MLS;
                pd->shape.nearest = 12;
            }
            err = frm_sampling_meshless(s, x, h.node_count, c, 8 * h.hex_count, (frm_real)0.25, &pd->shape, NULL);
            free(c);
        }
        hexmesh_free(&h);
    }
    free(x);
    if (err) return err;
    pd->elements = *elements;
    frm_sampling_apply(s, &d);
    d.material.young_modulus = (frm_real)1e5;
    return frm_model_create(&d, m);
}

/* Probes on every kind of model: at the samples' rest positions they give the model's
   sample positions (the same shape functions) in a random deformed state; under a rigid
   motion (rotation 0.7 rad, translation) any interior point moves rigidly, its velocity
   the rigid field's; the mid-points of the body's faces are found (boundary), points
   outside refused. */
static void test_probe_kinds(void)
{
    static const char *names[4] = {"tetrahedra", "hexahedra", "Shepard", "MLS"};
    double tol = IS_FLOAT ? 2e-6 : 1e-12, th = 0.7, n[3] = {1 / sqrt(14.0), 2 / sqrt(14.0), 3 / sqrt(14.0)}, R[9];
    double t[3] = {0.3, -0.2, 0.1}, w[3] = {0.2, -0.5, 0.3}, v0[3] = {1, 2, -1};
    int kind, i, r;
    { /* Rodrigues */
        double c = cos(th), sn = sin(th);
        for (i = 0; i < 3; i++)
            for (r = 0; r < 3; r++) {
                double k = i == r ? c : 0, e = 0;
                if ((i + 1) % 3 == r) e = -n[(i + 2) % 3];
                if ((i + 2) % 3 == r) e = n[(i + 1) % 3];
                R[3 * i + r] = k + (1 - c) * n[i] * n[r] + sn * e;
            }
    }
    for (kind = 0; kind < 4; kind++) {
        frm_model *m = NULL;
        frm_sampling s;
        frm_probe_desc pd;
        frm_probe *p = NULL;
        int *elements = NULL, nf, ns, k;
        frm_real *pos, *quat, *vel, *out, pts[3 * 24], outside[3] = {(frm_real)1.2, (frm_real)0.25, (frm_real)0.25};
        double worst_s = 0, worst_r = 0, worst_v = 0, worst_a = 0;
        unsigned seed = 7;
        REQUIRE(probe_scene(kind, &m, &s, &pd, &elements) == FRM_OK);
        nf = frm_model_frame_count(m);
        ns = frm_model_sample_count(m);
        pos = alloc_reals(3 * nf), quat = alloc_reals(4 * nf), vel = alloc_reals(6 * nf), out = alloc_reals(3 * ns);
        /* (a) the samples, random state */
        REQUIRE(frm_probe_create(m, &pd, s.sample_positions, ns, &p) == FRM_OK);
        CHECK_INT(ns, frm_probe_count(p));
        for (i = 0; i < nf; i++) {
            double a[3], an = 0;
            for (r = 0; r < 3; r++) {
                seed = seed * 1664525u + 1013904223u;
                pos[3 * i + r] = (frm_real)(s.frame_positions[3 * i + r] + 0.02 * (((seed >> 8) & 1023) / 512.0 - 1));
                seed = seed * 1664525u + 1013904223u;
                a[r] = 0.1 * (((seed >> 8) & 1023) / 512.0 - 1);
                an += a[r] * a[r];
            }
            an = sqrt(an);
            for (r = 0; r < 3; r++) quat[4 * i + r] = (frm_real)(an > 0 ? sin(an / 2) * a[r] / an : 0);
            quat[4 * i + 3] = (frm_real)cos(an / 2);
        }
        REQUIRE(frm_model_set_poses(m, pos, quat) == FRM_OK);
        REQUIRE(frm_probe_positions(p, m, out) == FRM_OK);
        {
            const frm_real *sp = frm_model_sample_positions(m);
            for (i = 0; i < 3 * ns; i++)
                if (fabs((double)out[i] - (double)sp[i]) > worst_s) worst_s = fabs((double)out[i] - (double)sp[i]);
        }
        CHECK(worst_s < 10 * tol);
        frm_probe_destroy(p);
        p = NULL;
        /* (b) rigid motion at interior points and the faces' mid-points */
        for (i = 0; i < 18; i++) {
            seed = seed * 1664525u + 1013904223u;
            pts[3 * i] = (frm_real)(0.05 + 0.9 * ((seed >> 8) & 1023) / 1023.0);
            seed = seed * 1664525u + 1013904223u;
            pts[3 * i + 1] = (frm_real)(0.025 + 0.45 * ((seed >> 8) & 1023) / 1023.0);
            seed = seed * 1664525u + 1013904223u;
            pts[3 * i + 2] = (frm_real)(0.025 + 0.45 * ((seed >> 8) & 1023) / 1023.0);
        }
        for (i = 18; i < 24; i++) { /* face centres */
            int axis = (i - 18) / 2, hiside = (i - 18) % 2;
            double ext[3] = {1, 0.5, 0.5};
            for (r = 0; r < 3; r++) pts[3 * i + r] = (frm_real)(r == axis ? hiside * ext[r] : ext[r] / 2);
        }
        REQUIRE(frm_probe_create(m, &pd, pts, 24, &p) == FRM_OK);
        {
            double qv[4];
            qv[3] = cos(th / 2);
            for (r = 0; r < 3; r++) qv[r] = sin(th / 2) * n[r];
            for (i = 0; i < nf; i++) {
                const frm_real *xb = s.frame_positions + 3 * i;
                double x[3];
                for (r = 0; r < 3; r++) x[r] = R[3 * r] * xb[0] + R[3 * r + 1] * xb[1] + R[3 * r + 2] * xb[2] + t[r];
                for (r = 0; r < 3; r++) pos[3 * i + r] = (frm_real)x[r];
                for (r = 0; r < 4; r++) quat[4 * i + r] = (frm_real)qv[r];
                vel[6 * i] = (frm_real)(v0[0] + w[1] * x[2] - w[2] * x[1]);
                vel[6 * i + 1] = (frm_real)(v0[1] + w[2] * x[0] - w[0] * x[2]);
                vel[6 * i + 2] = (frm_real)(v0[2] + w[0] * x[1] - w[1] * x[0]);
                for (r = 0; r < 3; r++) vel[6 * i + 3 + r] = (frm_real)w[r];
            }
        }
        REQUIRE(frm_model_set_poses(m, pos, quat) == FRM_OK);
        REQUIRE(frm_model_set_velocities(m, vel) == FRM_OK);
        {
            frm_real P[3 * 24], U[3 * 24], V[3 * 24];
            REQUIRE(frm_probe_positions(p, m, P) == FRM_OK);
            REQUIRE(frm_probe_displacements(p, m, U) == FRM_OK);
            REQUIRE(frm_probe_velocities(p, m, V) == FRM_OK);
            for (i = 0; i < 24; i++) {
                double x[3], vv[3];
                for (r = 0; r < 3; r++)
                    x[r] = R[3 * r] * pts[3 * i] + R[3 * r + 1] * pts[3 * i + 1] + R[3 * r + 2] * pts[3 * i + 2] + t[r];
                vv[0] = v0[0] + w[1] * x[2] - w[2] * x[1];
                vv[1] = v0[1] + w[2] * x[0] - w[0] * x[2];
                vv[2] = v0[2] + w[0] * x[1] - w[1] * x[0];
                for (r = 0; r < 3; r++) {
                    k = 3 * i + r;
                    if (fabs((double)P[k] - x[r]) > worst_r) worst_r = fabs((double)P[k] - x[r]);
                    if (fabs((double)U[k] - (x[r] - (double)pts[k])) > worst_r) worst_r = fabs((double)U[k] - (x[r] - (double)pts[k]));
                    if (fabs((double)V[k] - vv[r]) > worst_v) worst_v = fabs((double)V[k] - vv[r]);
                }
            }
        }
        if (kind != 2) { /* (c) an affine field x = A xbar + b of the frames' positions, no rotation: the
                            weights reproduce it at any point (Shepard does not: zero order) */
            static const double A[9] = {1.1, 0.2, -0.1, 0.05, 0.9, 0.3, -0.2, 0.1, 1.2}, b[3] = {0.1, 0.2, 0.3};
            frm_real P[3 * 24];
            for (i = 0; i < nf; i++) {
                const frm_real *xb = s.frame_positions + 3 * i;
                for (r = 0; r < 3; r++) {
                    pos[3 * i + r] = (frm_real)(A[3 * r] * xb[0] + A[3 * r + 1] * xb[1] + A[3 * r + 2] * xb[2] + b[r]);
                    quat[4 * i + r] = 0;
                }
                quat[4 * i + 3] = 1;
            }
            REQUIRE(frm_model_set_poses(m, pos, quat) == FRM_OK);
            REQUIRE(frm_probe_positions(p, m, P) == FRM_OK);
            for (i = 0; i < 24; i++)
                for (r = 0; r < 3; r++) {
                    double x = A[3 * r] * pts[3 * i] + A[3 * r + 1] * pts[3 * i + 1] + A[3 * r + 2] * pts[3 * i + 2] + b[r];
                    if (fabs((double)P[3 * i + r] - x) > worst_a) worst_a = fabs((double)P[3 * i + r] - x);
                }
            CHECK(worst_a < 10 * tol);
        }
        printf("    %-10s: samples %.1e m, rigid motion %.1e m, rigid velocity %.1e m/s, affine field %.1e m\n", names[kind],
               worst_s, worst_r, worst_v, worst_a);
        CHECK(worst_r < 10 * tol);
        CHECK(worst_v < 10 * tol);
        frm_probe_destroy(p);
        p = NULL;
        if (kind < 2) CHECK_INT(FRM_ERR_POINT_OUTSIDE, frm_probe_create(m, &pd, outside, 1, &p));
        CHECK(p == NULL);
        free(pos), free(quat), free(vel), free(out), free(elements);
        frm_model_destroy(m);
        frm_sampling_free(&s);
    }
}

/* Probe refusals: a description not made by its default function, NULL and counts,
   non-finite points, element indices out of range, a probe used with another model. */
static void test_probe_refusals(void)
{
    frm_model *m = NULL, *other = NULL;
    frm_sampling s, s2;
    frm_probe_desc pd, garbage;
    frm_probe *p = (frm_probe *)&p;
    int *elements = NULL, *el2 = NULL, saved;
    frm_real pt[3] = {(frm_real)0.5, (frm_real)0.25, (frm_real)0.25}, nan_pt[3] = {0, 0, 0}, out[3];
    REQUIRE(probe_scene(1, &m, &s, &pd, &elements) == FRM_OK);
    memset(&garbage, 0xA5, sizeof garbage);
    CHECK_INT(FRM_ERR_DESC, frm_probe_create(m, &garbage, pt, 1, &p));
    CHECK(p == NULL);
    CHECK_INT(FRM_ERR_ARG, frm_probe_create(NULL, &pd, pt, 1, &p));
    CHECK_INT(FRM_ERR_ARG, frm_probe_create(m, &pd, pt, 0, &p));
    CHECK_INT(FRM_ERR_ARG, frm_probe_create(m, &pd, NULL, 1, &p));
    nan_pt[1] = (frm_real)NAN;
    CHECK_INT(FRM_ERR_ARG, frm_probe_create(m, &pd, nan_pt, 1, &p));
    saved = elements[5];
    elements[5] = frm_model_frame_count(m);
    CHECK_INT(FRM_ERR_INDEX_RANGE, frm_probe_create(m, &pd, pt, 1, &p));
    elements[5] = saved;
    pd.shape.nearest = 0;
    pd.kind = FRM_PROBE_MESHLESS;
    CHECK_INT(FRM_ERR_SAMPLING, frm_probe_create(m, &pd, pt, 1, &p));
    pd.kind = FRM_PROBE_HEXES;
    REQUIRE(frm_probe_create(m, &pd, pt, 1, &p) == FRM_OK);
    REQUIRE(probe_scene(0, &other, &s2, &pd, &el2) == FRM_OK);
    if (frm_model_frame_count(other) != frm_model_frame_count(m)) CHECK_INT(FRM_ERR_ARG, frm_probe_positions(p, other, out));
    CHECK_INT(FRM_ERR_ARG, frm_probe_velocities(p, m, NULL));
    CHECK_INT(FRM_OK, frm_probe_displacements(p, m, out));
    CHECK(out[0] == 0 && out[1] == 0 && out[2] == 0); /* the rest state */
    frm_probe_destroy(p);
    frm_probe_destroy(NULL);
    free(elements), free(el2);
    frm_model_destroy(m), frm_model_destroy(other);
    frm_sampling_free(&s), frm_sampling_free(&s2);
}


/* ---- issue 19: modal analysis -------------------------------------------------------- */

/* |X^T M X - I| over the lowest `count` modes (M from the mass blocks). */
static double modal_orthonormality(const frm_modal *md, frm_model *m, int count)
{
    int F = frm_model_frame_count(m), a, b, i, r, c;
    double worst = 0;
    for (a = 0; a < count; a++)
        for (b = 0; b <= a; b++) {
            const frm_real *x = frm_modal_shape(md, a), *y = frm_modal_shape(md, b);
            double t = 0;
            for (i = 0; i < F; i++) {
                frm_real B[36];
                if (frm_model_frame_state(m, i) != 0) continue;
                frm_model_mass_block(m, i, B);
                for (r = 0; r < 6; r++)
                    for (c = 0; c < 6; c++) t += (double)x[6 * i + r] * (double)B[6 * r + c] * (double)y[6 * i + c];
            }
            t -= a == b;
            if (fabs(t) > worst) worst = fabs(t);
        }
    return worst;
}

/* The R3 beam of tetrahedral frames one cell across: the modal solver's lowest 8
   frequencies against the dense eigenvalues of the same linearised model (model_modes), to
   1e-6 relative, modes M-orthonormal to 1e-9; two cells across (full builds): the 3D
   frequencies of REFERENCES R3 within the discretisation's error (bending pair within 3 %:
   the model's static sag is +4.6 % of beam theory; second bending within 3 %; torsion
   4.85 Hz against 4.51, +8 %, the divergence term's coarse-resolution stiffening, see
   LIMITS) and no mode below 0.95 x 0.5091 Hz (no spurious mode). Deterministic: a second
   solve gives the same bits. */
static void test_modal_r3(void)
{
    int k;
    for (k = 1; k <= (TEST_IS_QUICK ? 1 : 2); k++) {
        frm_sampling s;
        frm_model *m;
        frm_modal *md = NULL;
        frm_modal_desc d = frm_modal_default_desc();
        double tol = IS_FLOAT ? 2e-3 : 1e-6, orth;
        int i, n;
        REQUIRE(tet_beam(&s, &m, k, (double)frm_model_default_desc().rotation_divergence) == FRM_OK);
        d.count = k == 1 ? 8 : 5; /* two cells across: the five modes R3 gives, to 1e-6 (test time) */
        if (k == 2 && !IS_FLOAT) d.tolerance = (frm_real)1e-6;
        REQUIRE(frm_modal_create(m, &d, &md) == FRM_OK);
        REQUIRE(frm_modal_solve(md, m) == FRM_OK);
        CHECK_INT(d.count, frm_modal_count(md));
        printf("    R3 tet frames %d cell(s) across, modal (%d CG iterations):", k, frm_model_last_stats(m)->cg_iterations);
        for (i = 0; i < d.count; i++) printf(" %.4f", frm_modal_frequency(md, i));
        printf(" Hz\n");
        orth = modal_orthonormality(md, m, d.count);
        CHECK(orth < (IS_FLOAT ? 1e-4 : 1e-9));
        if (k == 1) {
            double *freq = (double *)calloc((size_t)6 * s.frame_count, sizeof(double)), rot[8];
            frm_real *x0 = alloc_reals(6 * s.frame_count);
            n = model_modes(m, freq, rot, 8);
            REQUIRE(n >= 8);
            for (i = 0; i < 8; i++) CHECK_REL(freq[i], frm_modal_frequency(md, i), tol);
            memcpy(x0, frm_modal_shape(md, 0), sizeof(frm_real) * 6 * (size_t)s.frame_count);
            REQUIRE(frm_modal_solve(md, m) == FRM_OK);
            CHECK(memcmp(x0, frm_modal_shape(md, 0), sizeof(frm_real) * 6 * (size_t)s.frame_count) == 0);
            printf("    dense: %.4f %.4f %.4f %.4f Hz; M-orthonormality %.1e\n", freq[0], freq[1], freq[2], freq[3], orth);
            free(freq), free(x0);
        } else {
            CHECK(frm_modal_frequency(md, 0) > 0.95 * 0.5091);
            CHECK_REL(0.5091, frm_modal_frequency(md, 0), 0.03);
            CHECK_REL(0.5091, frm_modal_frequency(md, 1), 0.03);
            CHECK_REL(3.0531, frm_modal_frequency(md, 2), 0.03);
            CHECK_REL(3.0531, frm_modal_frequency(md, 3), 0.03);
            CHECK_REL(4.5101, frm_modal_frequency(md, 4), 0.09);
        }
        frm_modal_destroy(md);
        frm_model_destroy(m);
        frm_sampling_free(&s);
    }
}

/* Closed forms: a free cube (2 x 2 x 2 hexahedral cells, nothing held, no gravity) has six
   rigid modes at 0 Hz (below 1e-6 of the next, which is > 0.1 Hz) with frame_coupling 1e-2.
   The default model (no coupling) has 11 (measured): the six rigid modes, every frame
   turning alike (it moves no material and F stays a rotation: no term sees it) and two
   more frame-rotation mechanisms of this coarse grid (see LIMITS in frames.h); a clamped-free
   bar (1 m, 20 x 1 x 1 cells, E = 1 MPa, nu = 0, rho = 1000) whose frames may only move
   along the axis (held axes) has the axial modes f_n = (2 n - 1) c / 4 L, c = sqrt(E /
   rho), within the linear elements' dispersion (kh)^2 / 24 (0.03 % and 0.23 % for the first
   two; checked to 0.5 %). Bad descriptions and arguments are refused. */
static void test_modal_closed_forms(void)
{
    frm_sampling s;
    frm_model *m;
    frm_modal *md = NULL;
    frm_modal_desc d = frm_modal_default_desc(), garbage;
    int i;
    {
        hexmesh h;
        frm_desc dd = frm_model_default_desc();
        double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
        frm_real *x;
        REQUIRE(hexmesh_grid(&h, lo, hi, 2, 2, 2) == TETMESH_OK);
        x = alloc_reals(3 * h.node_count);
        for (i = 0; i < 3 * h.node_count; i++) x[i] = (frm_real)h.nodes[i];
        REQUIRE(frm_sampling_hexes(&s, x, h.node_count, h.hexes, h.hex_count, 2, FRM_QUADRATURE_SUBCELL, NULL) == FRM_OK);
        free(x);
        hexmesh_free(&h);
        frm_sampling_apply(&s, &dd);
        dd.material.young_modulus = (frm_real)1e5;
        dd.gravity[2] = 0;
        dd.frame_coupling = (frm_real)1e-2; /* without it, 11 zero modes: see the comment above */
        REQUIRE(frm_model_create(&dd, &m) == FRM_OK);
    }
    d.count = 12;
    REQUIRE(frm_modal_create(m, &d, &md) == FRM_OK);
    REQUIRE(frm_modal_solve(md, m) == FRM_OK);
    printf("    free cube:");
    for (i = 0; i < 12; i++) printf(" %.3g", frm_modal_frequency(md, i));
    printf(" Hz; M-orthonormality %.1e\n", modal_orthonormality(md, m, 12));
    for (i = 0; i < 6; i++) CHECK(frm_modal_frequency(md, i) < (IS_FLOAT ? 1e-2 : 1e-6) * frm_modal_frequency(md, 6));
    CHECK(frm_modal_frequency(md, 6) > 0.1);
    CHECK(modal_orthonormality(md, m, 12) < (IS_FLOAT ? 1e-4 : 1e-9));
    CHECK(frm_modal_frequency(md, 12) == -1 && frm_modal_shape(md, 12) == NULL);
    memset(&garbage, 0xA5, sizeof garbage);
    {
        frm_modal *bad = (frm_modal *)&bad;
        CHECK_INT(FRM_ERR_DESC, frm_modal_create(m, &garbage, &bad));
        CHECK(bad == NULL);
        garbage = frm_modal_default_desc();
        garbage.count = 0;
        CHECK_INT(FRM_ERR_ARG, frm_modal_create(m, &garbage, &bad));
        garbage = frm_modal_default_desc();
        garbage.tolerance = 0;
        CHECK_INT(FRM_ERR_ARG, frm_modal_create(m, &garbage, &bad));
    }
    frm_modal_destroy(md);
    frm_model_destroy(m);
    frm_sampling_free(&s);
    { /* the axial bar */
        hexmesh h;
        frm_desc dd = frm_model_default_desc();
        double lo[3] = {0, -0.05, -0.05}, hi[3] = {1, 0.05, 0.05}, c = sqrt(1e6 / 1000.0);
        frm_real *x;
        REQUIRE(hexmesh_grid(&h, lo, hi, 20, 1, 1) == TETMESH_OK);
        x = alloc_reals(3 * h.node_count);
        for (i = 0; i < 3 * h.node_count; i++) x[i] = (frm_real)h.nodes[i];
        for (i = 0; i < h.node_count; i++)
            if (fabs(h.nodes[3 * i]) < 1e-12) x[3 * i] = 0;
        REQUIRE(frm_sampling_hexes(&s, x, h.node_count, h.hexes, h.hex_count, 2, FRM_QUADRATURE_SUBCELL, NULL) == FRM_OK);
        free(x);
        hexmesh_free(&h);
        frm_sampling_apply(&s, &dd);
        dd.material.young_modulus = (frm_real)1e6;
        dd.material.poisson_ratio = 0;
        dd.material.density = 1000;
        dd.gravity[2] = 0;
        REQUIRE(frm_model_create(&dd, &m) == FRM_OK);
        for (i = 0; i < s.frame_count; i++)
            if (s.frame_positions[3 * i] == 0) frm_model_fix_frame(m, i);
            else frm_model_set_frame_axes(m, i, 6, 7);
        d = frm_modal_default_desc();
        d.count = 2;
        REQUIRE(frm_modal_create(m, &d, &md) == FRM_OK);
        REQUIRE(frm_modal_solve(md, m) == FRM_OK);
        printf("    axial bar: %.5f, %.5f Hz (closed form %.5f, %.5f)\n", frm_modal_frequency(md, 0), frm_modal_frequency(md, 1),
               c / 4, 3 * c / 4);
        CHECK_REL(c / 4, frm_modal_frequency(md, 0), 0.005);
        CHECK_REL(3 * c / 4, frm_modal_frequency(md, 1), 0.005);
        frm_modal_destroy(md);
        frm_model_destroy(m);
        frm_sampling_free(&s);
    }
}


/* The principal root r e^{i theta} of implicit Euler (1 / (1 - i eps)) or BDF2 ((2 + sqrt(1 +
   2 i eps)) / (3 - 2 i eps)) on x'' = -w^2 x, eps = w dt (as tests/test_frames.c's). */
static void scheme_root(int bdf2, double eps, double *r, double *theta)
{
    double re, im;
    if (!bdf2) {
        re = 1 / (1 + eps * eps);
        im = eps / (1 + eps * eps);
    } else {
        double mod = sqrt(1 + 4 * eps * eps), sa = sqrt((mod + 1) / 2), sb = sqrt((mod - 1) / 2);
        double nr = 2 + sa, ni = sb, dr = 3, di = -2 * eps, d2 = dr * dr + di * di;
        re = (nr * dr + ni * di) / d2;
        im = (ni * dr - nr * di) / d2;
    }
    *r = sqrt(re * re + im * im);
    *theta = atan2(im, re);
}

/* The R3 beam's first mode (tetrahedral frames one cell across) by frm_modal: the beam
   released from a small displacement along that mode shape stays in it (linear regime), so
   its modal coordinate phi^T M u is a one-degree-of-freedom oscillator of the model's own
   frequency: fitted per step like test_i19_oscillator_decay's, its amplitude decay a
   period and period error at dt = T/20, T/40, T/80 for implicit Euler and BDF2 match the
   schemes' closed-form roots (decay to 1e-3 relative at T/20 and T/40, period error to 2 %;
   BDF2's period error falls 4 times a halving of dt, 3.6 to 4.4 from T/40 to T/80).
   Measured: the closed forms to 5 digits (at T/20..T/100, 3 periods). */
static void test_modal_r3_time_order(void)
{
    static const int per_period[3] = {20, 40, 80};
    frm_sampling s;
    frm_model *m;
    frm_modal *md = NULL;
    frm_modal_desc d = frm_modal_default_desc();
    double w, T, amp = IS_FLOAT ? 1e-4 : 1e-7, perr[2][3], pi = 3.14159265358979323846;
    frm_real *phi, *pos, *quat, B[36];
    double *Mphi;
    int integ, c, i, k, F;
    REQUIRE(tet_beam(&s, &m, 1, (double)frm_model_default_desc().rotation_divergence) == FRM_OK);
    F = frm_model_frame_count(m);
    d.count = 1;
    REQUIRE(frm_modal_create(m, &d, &md) == FRM_OK);
    REQUIRE(frm_modal_solve(md, m) == FRM_OK);
    w = 2 * pi * frm_modal_frequency(md, 0);
    T = 2 * pi / w;
    phi = alloc_reals(6 * F), pos = alloc_reals(3 * F), quat = alloc_reals(4 * F);
    Mphi = (double *)calloc((size_t)6 * F, sizeof(double));
    memcpy(phi, frm_modal_shape(md, 0), sizeof(frm_real) * 6 * (size_t)F);
    for (i = 0; i < F; i++) {
        REQUIRE(frm_model_mass_block(m, i, B) == FRM_OK);
        for (k = 0; k < 6; k++) {
            int l;
            for (l = 0; l < 6; l++) Mphi[6 * i + k] += (double)B[6 * k + l] * (double)phi[6 * i + l];
        }
    }
    frm_modal_destroy(md);
    frm_model_destroy(m);
    for (integ = TEST_IS_QUICK ? 1 : 0; integ < 2; integ++) /* quick builds: BDF2 at T/20 and T/40 */
        for (c = 0; c < (TEST_IS_QUICK ? 2 : 3); c++) {
            frm_desc dd = frm_model_default_desc();
            double dt = T / per_period[c], *x, S11 = 0, S12 = 0, S22 = 0, R1 = 0, R2 = 0, fa, fc, r, th, r0, th0, decay, decay0;
            int steps = 20 + 3 * per_period[c] / 2, n; /* a period and a half after the start */
            frm_sampling_apply(&s, &dd);
            dd.material.young_modulus = (frm_real)1e6;
            dd.gravity[2] = 0;
            dd.parallel_min_pairs = 1 << 30;
            dd.integrator = integ ? FRM_BDF2 : FRM_IMPLICIT_EULER;
            REQUIRE(frm_model_create(&dd, &m) == FRM_OK);
            REQUIRE(frm_model_set_solver(m, (frm_real)(IS_FLOAT ? 1e-6 : 1e-12), 5000, (frm_real)(IS_FLOAT ? 1e-5 : 1e-10), 30) ==
                    FRM_OK);
            for (i = 0; i < F; i++) {
                double t[3], tn;
                if (s.frame_positions[3 * i] == 0) frm_model_fix_frame(m, i);
                for (k = 0; k < 3; k++) {
                    pos[3 * i + k] = (frm_real)(s.frame_positions[3 * i + k] + amp * phi[6 * i + k]);
                    t[k] = amp * phi[6 * i + 3 + k];
                }
                tn = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
                for (k = 0; k < 3; k++) quat[4 * i + k] = (frm_real)(tn > 0 ? sin(tn / 2) * t[k] / tn : 0);
                quat[4 * i + 3] = (frm_real)cos(tn / 2);
            }
            REQUIRE(frm_model_set_poses(m, pos, quat) == FRM_OK);
            x = (double *)calloc((size_t)steps + 1, sizeof(double));
            for (n = 1; n <= steps; n++) {
                REQUIRE(frm_model_step_ex(m, (frm_real)dt) == FRM_OK);
                for (i = 0; i < F; i++)
                    for (k = 0; k < 3; k++)
                        x[n] += Mphi[6 * i + k] * ((double)frm_model_positions(m)[3 * i + k] - s.frame_positions[3 * i + k]) +
                                Mphi[6 * i + 3 + k] * 2 * (double)frm_model_orientations(m)[4 * i + k];
            }
            for (n = 21; n < steps; n++) {
                S11 += x[n] * x[n], S12 += x[n] * x[n - 1], S22 += x[n - 1] * x[n - 1];
                R1 += x[n + 1] * x[n], R2 += x[n + 1] * x[n - 1];
            }
            fa = (R1 * S22 - R2 * S12) / (S11 * S22 - S12 * S12);
            fc = (S11 * R2 - S12 * R1) / (S11 * S22 - S12 * S12);
            r = sqrt(-fc);
            th = acos(fa / (2 * r));
            scheme_root(integ, w * dt, &r0, &th0);
            decay = 1 - pow(r, 2 * pi / th);
            decay0 = 1 - pow(r0, 2 * pi / th0);
            perr[integ][c] = w * dt / th - 1;
            printf("    R3 mode 1 (%.4f Hz), %s T/%d: decay a period %.4e (theory %.4e), period error %+.4e (theory %+.4e)\n",
                   w / (2 * pi), integ ? "BDF2          " : "implicit Euler", per_period[c], decay, decay0, perr[integ][c],
                   w * dt / th0 - 1);
            if (!IS_FLOAT && per_period[c] <= 40) CHECK_REL(decay0, decay, 1e-3);
            if (!IS_FLOAT) CHECK_REL(w * dt / th0 - 1, perr[integ][c], 0.02);
            free(x);
            frm_model_destroy(m);
        }
    if (!TEST_IS_QUICK) {
        printf("    R3 mode 1, T/40 -> T/80: period error / %.2f (implicit Euler), / %.2f (BDF2)\n", perr[0][1] / perr[0][2],
               perr[1][1] / perr[1][2]);
        if (!IS_FLOAT) CHECK(perr[1][1] / perr[1][2] > 3.6 && perr[1][1] / perr[1][2] < 4.4);
    }
    free(phi), free(pos), free(quat), free(Mphi);
    frm_sampling_free(&s);
}


/* Many points in a larger mesh (1,600 tetrahedra, 5,000 points: random, and every node):
   each found through the element bins, exact under an affine field of the frames
   (weights of the containing tetrahedron), in milliseconds. */
static void test_probe_many(void)
{
    double lo[3] = {0, 0, 0}, hi[3] = {4, 0.8, 0.8};
    static const double A[9] = {1.1, 0.2, -0.1, 0.05, 0.9, 0.3, -0.2, 0.1, 1.2}, b[3] = {0.1, 0.2, 0.3};
    tetmesh t;
    frm_sampling s;
    frm_desc d = frm_model_default_desc();
    frm_probe_desc pd = frm_probe_default_desc();
    frm_model *m = NULL;
    frm_probe *p = NULL;
    frm_real *x, *pts, *pos, *quat, *out;
    int i, r, count, nodes;
    unsigned seed = 11;
    double worst = 0, t0;
    REQUIRE(tetmesh_box(&t, lo, hi, 20, 4, 4, TETMESH_SPLIT5) == TETMESH_OK);
    nodes = t.node_count;
    count = 5000 > nodes ? 5000 : nodes;
    x = alloc_reals(3 * nodes), pts = alloc_reals(3 * count), pos = alloc_reals(3 * nodes), quat = alloc_reals(4 * nodes);
    out = alloc_reals(3 * count);
    for (i = 0; i < 3 * nodes; i++) x[i] = (frm_real)t.nodes[i];
    REQUIRE(frm_sampling_tets(&s, x, nodes, t.tets, t.tet_count, 1, NULL, NULL) == FRM_OK);
    frm_sampling_apply(&s, &d);
    REQUIRE(frm_model_create(&d, &m) == FRM_OK);
    for (i = 0; i < count; i++)
        for (r = 0; r < 3; r++) {
            seed = seed * 1664525u + 1013904223u;
            pts[3 * i + r] = i < nodes ? x[3 * i + r] : (frm_real)(hi[r] * (((seed >> 8) & 0xFFFF) / 65535.0));
        }
    pd.kind = FRM_PROBE_TETS;
    pd.elements = t.tets;
    pd.element_count = t.tet_count;
    t0 = (double)clock();
    REQUIRE(frm_probe_create(m, &pd, pts, count, &p) == FRM_OK);
    t0 = ((double)clock() - t0) / CLOCKS_PER_SEC;
    for (i = 0; i < nodes; i++) {
        for (r = 0; r < 3; r++) {
            pos[3 * i + r] = (frm_real)(A[3 * r] * x[3 * i] + A[3 * r + 1] * x[3 * i + 1] + A[3 * r + 2] * x[3 * i + 2] + b[r]);
            quat[4 * i + r] = 0;
        }
        quat[4 * i + 3] = 1;
    }
    REQUIRE(frm_model_set_poses(m, pos, quat) == FRM_OK);
    REQUIRE(frm_probe_positions(p, m, out) == FRM_OK);
    for (i = 0; i < count; i++)
        for (r = 0; r < 3; r++) {
            double e = A[3 * r] * pts[3 * i] + A[3 * r + 1] * pts[3 * i + 1] + A[3 * r + 2] * pts[3 * i + 2] + b[r];
            if (fabs(e - (double)out[3 * i + r]) > worst) worst = fabs(e - (double)out[3 * i + r]);
        }
    printf("    %d points in %d tetrahedra: found in %.3f s, affine field %.1e m\n", count, t.tet_count, t0, worst);
    CHECK(worst < (IS_FLOAT ? 1e-5 : 1e-12));
    frm_probe_destroy(p);
    frm_model_destroy(m);
    frm_sampling_free(&s);
    tetmesh_free(&t);
    free(x), free(pts), free(pos), free(quat), free(out);
}


/* ---- issue 13: volumetric averaging (F-bar) against volumetric locking ---------------- */

static const char *vol_name(int mode)
{
    return mode == FRM_VOLUMETRIC_CELLS ? "cells" : mode == FRM_VOLUMETRIC_FRAMES ? "frames" : "patches";
}

/* A small body for the volumetric tests: mode CELLS, 2 x 1 x 1 hexahedral cells of 8
   Gauss samples (12 frames); modes FRAMES and PATCHES, the same box in 10 tetrahedra with
   one sample each (PATCHES: the tests set patches of 4, VOL_PATCH: 3 patches of 4, 4 and
   2 samples, so the averaging couples samples within a patch and not across). Nodes perturbed by `jitter` (an
   unstructured mesh). */
#define VOL_PATCH 4

static int vol_body(int mode, double jitter, frm_sampling *s, frm_real **nodes_out, int *node_count)
{
    frm_real *x;
    int i, err, n;
    unsigned seed = 777u;
    if (mode == FRM_VOLUMETRIC_CELLS) {
        int hex[16], c, a;
        n = 12;
        x = alloc_reals(3 * n);
        for (i = 0; i < n; i++) {
            x[3 * i] = (frm_real)(0.5 * (i % 3));
            x[3 * i + 1] = (frm_real)(0.5 * (i / 3 % 2));
            x[3 * i + 2] = (frm_real)(0.5 * (i / 6));
        }
        for (c = 0; c < 2; c++)
            for (a = 0; a < 8; a++) hex[8 * c + a] = (c + (a & 1)) + 3 * ((a >> 1 & 1) + 2 * (a >> 2));
        for (i = 0; i < 3 * n; i++) x[i] = (frm_real)((double)x[i] + jitter * law_rand(&seed));
        err = frm_sampling_hexes(s, x, n, hex, 2, 2, FRM_QUADRATURE_GAUSS, NULL);
    } else {
        tetmesh t;
        if (tetmesh_beam(&t, 1, 0.5, 0.5, 2, 1, 1, TETMESH_SPLIT5) != TETMESH_OK) return -1;
        n = t.node_count;
        x = alloc_reals(3 * n);
        for (i = 0; i < 3 * n; i++) x[i] = (frm_real)(t.nodes[i] + jitter * law_rand(&seed));
        err = frm_sampling_tets(s, x, n, t.tets, t.tet_count, 1, NULL, NULL);
        tetmesh_free(&t);
    }
    if (nodes_out) *nodes_out = x;
    else free(x);
    if (node_count) *node_count = n;
    return err;
}

/* The energy of the F-bar model computed here from the model's output F (independent of
   its force code): J_bar = the averaging of MODEL (cells: volume-weighted mean J of the
   cell; frames: J averaged at the frames with weights v_s w_si, interpolated back with
   w_si), F_bar = (J_bar / J)^(1/3) F, E = sum_s v_s (W(F_bar_s) + eta mu / 2 ln^2(J_bar / J)) through
   the law table (eta_mu = eta mu, the stabilisation's stiffness). cells: each sample's cell
   (CELLS: the sampling's; PATCHES: the model's patches, whose partition
   test_vol_patches_partition checks), NULL for FRAMES, with `groups` cells. */
static double vol_energy(const frm_sampling *s, const int *cells, int groups, int law, const frm_real *prm,
                         const frm_user_law *user, double eta_mu, const frm_real *F)
{
    int S = s->sample_count, n = s->frame_count, t, e, k, mode = cells ? FRM_VOLUMETRIC_CELLS : FRM_VOLUMETRIC_FRAMES;
    double *J, *num, *den, E = 0;
    if (!cells) groups = n;
    J = (double *)calloc((size_t)S, sizeof(double)), num = (double *)calloc((size_t)groups, sizeof(double));
    den = (double *)calloc((size_t)groups, sizeof(double));
    for (t = 0; t < S; t++) {
        const frm_real *f = F + 9 * t;
        J[t] = (double)f[0] * ((double)f[4] * f[8] - (double)f[5] * f[7]) - (double)f[1] * ((double)f[3] * f[8] - (double)f[5] * f[6]) +
               (double)f[2] * ((double)f[3] * f[7] - (double)f[4] * f[6]);
        for (e = s->neighbor_start[t]; e < s->neighbor_start[t + 1]; e++) {
            int g = mode == FRM_VOLUMETRIC_CELLS ? cells[t] : s->neighbor_frames[e];
            double w = mode == FRM_VOLUMETRIC_CELLS ? 1.0 : (double)s->neighbor_weights[e];
            num[g] += (double)s->sample_volumes[t] * w * J[t];
            den[g] += (double)s->sample_volumes[t] * w;
            if (mode == FRM_VOLUMETRIC_CELLS) break;
        }
    }
    for (t = 0; t < S; t++) {
        double Jb = 0, al;
        frm_real H[9], psi;
        if (mode == FRM_VOLUMETRIC_CELLS) Jb = num[cells[t]] / den[cells[t]];
        else
            for (e = s->neighbor_start[t]; e < s->neighbor_start[t + 1]; e++)
                Jb += (double)s->neighbor_weights[e] * num[s->neighbor_frames[e]] / den[s->neighbor_frames[e]];
        al = cbrt(Jb / J[t]);
        for (k = 0; k < 9; k++) H[k] = (frm_real)(al * (double)F[9 * t + k] - (k % 4 == 0 ? 1 : 0));
        if (frm__laws[law].energy(prm, user, H, &psi) != 0) E = NAN;
        E += (double)s->sample_volumes[t] * ((double)psi + 0.5 * eta_mu * log(Jb / J[t]) * log(Jb / J[t]));
    }
    free(J);
    free(num);
    free(den);
    return E;
}

/* Random poses around rest: positions moved by `amp` m, rotations up to `rot` rad. */
static void vol_random_poses(const frm_real *x0, int n, double amp, double rot, unsigned *seed, frm_real *pos, frm_real *quat)
{
    int i, k;
    for (i = 0; i < n; i++) {
        double th[3], a;
        for (k = 0; k < 3; k++) pos[3 * i + k] = (frm_real)((double)x0[3 * i + k] + amp * law_rand(seed));
        for (k = 0; k < 3; k++) th[k] = rot * law_rand(seed);
        a = sqrt(th[0] * th[0] + th[1] * th[1] + th[2] * th[2]);
        for (k = 0; k < 3; k++) quat[4 * i + k] = (frm_real)(sin(0.5 * a) * th[k] / a);
        quat[4 * i + 3] = (frm_real)cos(0.5 * a);
    }
}

/* With the option on, per averaging mode and law: force = -gradient of vol_energy (every
   translation by central differences), K v = -d(force)/dq along random directions (the
   exact derivative, rotations included), and with the default stabilisation on the same
   K v check (the F-bar stress joins the stabilisation's). Tolerances: central differences
   with h = 1e-6 (double) leave O(h^2) ~ 1e-10 relative truncation and eps / h ~ 1e-10
   round-off; 1e-6 as test_law_model_path; float h = 1e-3, 5e-3 for its 1e-7 round-off / h. */
static void test_vol_derivatives(void)
{
    double h = IS_FLOAT ? 1e-3 : 1e-6, tol = IS_FLOAT ? 5e-3 : 1e-6;
    int mode, law, i, k, stab;
    for (mode = FRM_VOLUMETRIC_CELLS; mode <= FRM_VOLUMETRIC_PATCHES; mode++)
        for (law = 0; law < FRM_LAW_COUNT; law++)
            for (stab = 0; stab < 2; stab++) {
                frm_sampling s;
                frm_desc d;
                frm_model *m = NULL;
                frm_real *x0, *pos, *pos0, *quat, *q, *v, *Kv, *fp, *fm;
                const frm_real *f;
                frm_real prm[FRM_LAW_PARAMS], mu;
                frm_material mat = law_material(law);
                const frm_user_law *user = law == FRM_LAW_USER ? &mat.user : NULL;
                double worst_f = 0, worst_k = 0, fn = 0, kn = 0;
                unsigned seed = 4242u;
                const int *cells;
                int n, N, a, side, groups;
                REQUIRE(vol_body(mode, 0.05, &s, &x0, &n) == FRM_OK);
                N = 6 * n;
                pos = alloc_reals(3 * n), pos0 = alloc_reals(3 * n), quat = alloc_reals(4 * n), q = alloc_reals(4 * n);
                v = alloc_reals(N), Kv = alloc_reals(N), fp = alloc_reals(N), fm = alloc_reals(N);
                d = frm_model_default_desc();
                frm_sampling_apply(&s, &d);
                d.material = mat;
                d.volumetric = (frm_volumetric)mode;
                d.volumetric_patch_size = VOL_PATCH;
                d.volumetric_stabilization = (frm_real)(law == FRM_LAW_SVK ? 0 : 1.5); /* off and on */
                if (!stab) d.rotation_stabilization = 0, d.rotation_divergence = 0;
                d.gravity[0] = d.gravity[1] = d.gravity[2] = 0;
                REQUIRE(frm_model_create(&d, &m) == FRM_OK);
                cells = mode == FRM_VOLUMETRIC_CELLS ? s.sample_cells : mode == FRM_VOLUMETRIC_PATCHES ? m->ve_group : NULL;
                groups = mode == FRM_VOLUMETRIC_CELLS ? s.cell_count : m->vol_groups;
                if (mode == FRM_VOLUMETRIC_PATCHES) CHECK(groups >= 2);
                frm__law_params(&mat, prm, &mu);
                vol_random_poses(x0, n, 0.06, 0.1, &seed, pos0, quat);
                REQUIRE(frm_model_set_poses(m, pos0, quat) == FRM_OK);
                REQUIRE(frm_model_forces(m, &f) == FRM_OK);
                for (i = 0; i < N; i++) fn = fmax(fn, fabs((double)f[i]));
                memcpy(fp, f, sizeof(frm_real) * N);
                if (!stab)
                    for (i = 0; i < n; i++)
                        for (a = 0; a < 3; a++) {
                            double W[2];
                            for (side = 0; side < 2; side++) {
                                memcpy(pos, pos0, sizeof(frm_real) * 3 * n);
                                pos[3 * i + a] = (frm_real)((double)pos0[3 * i + a] + (side ? -h : h));
                                REQUIRE(frm_model_set_poses(m, pos, quat) == FRM_OK);
                                W[side] = vol_energy(&s, cells, groups, law, prm, user, (double)d.volumetric_stabilization * mu,
                                                     frm_model_deformation_gradients(m));
                            }
                            worst_f = fmax(worst_f, fabs(-(W[0] - W[1]) / (2 * h) - (double)fp[6 * i + a]) / fn);
                        }
                REQUIRE(frm_model_set_poses(m, pos0, quat) == FRM_OK);
                for (i = 0; i < N; i++) v[i] = (frm_real)law_rand(&seed);
                REQUIRE(frm_model_prepare_stiffness(m) == FRM_OK);
                REQUIRE(frm_model_apply_stiffness(m, v, Kv, 0) == FRM_OK);
                for (side = 0; side < 2; side++) {
                    double e = side ? -h : h;
                    for (i = 0; i < n; i++) {
                        frm_real th[3];
                        for (k = 0; k < 3; k++) {
                            pos[3 * i + k] = (frm_real)((double)pos0[3 * i + k] + e * (double)v[6 * i + k]);
                            th[k] = (frm_real)(e * (double)v[6 * i + 3 + k]);
                        }
                        memcpy(q + 4 * i, quat + 4 * i, 4 * sizeof(frm_real));
                        frm_quat_integrate(q + 4 * i, th);
                    }
                    REQUIRE(frm_model_set_poses(m, pos, q) == FRM_OK);
                    REQUIRE(frm_model_forces(m, &f) == FRM_OK);
                    memcpy(side ? fm : fp, f, sizeof(frm_real) * N);
                }
                for (i = 0; i < N; i++) kn = fmax(kn, fabs((double)Kv[i]));
                for (i = 0; i < N; i++) worst_k = fmax(worst_k, fabs(-((double)fp[i] - (double)fm[i]) / (2 * h) - (double)Kv[i]) / kn);
                printf("    %-6s %-20s stab %d: force vs -grad W %.1e, K v vs -d(force) %.1e\n",
                       vol_name(mode), frm__laws[law].name, stab, worst_f, worst_k);
                CHECK(worst_f < tol);
                CHECK(worst_k < tol);
                frm_model_destroy(m);
                frm_sampling_free(&s);
                free(x0), free(pos), free(pos0), free(quat), free(q), free(v), free(Kv), free(fp), free(fm);
            }
}

/* Rotation matrix (row-major) and quaternion (x, y, z, w) of the rotation by angle a about
   the unit axis n. */
static void vol_rotation(const double n[3], double a, double R[9], frm_real q[4])
{
    double c = cos(a), s = sin(a), t = 1 - c;
    int k;
    R[0] = c + t * n[0] * n[0], R[1] = t * n[0] * n[1] - s * n[2], R[2] = t * n[0] * n[2] + s * n[1];
    R[3] = t * n[0] * n[1] + s * n[2], R[4] = c + t * n[1] * n[1], R[5] = t * n[1] * n[2] - s * n[0];
    R[6] = t * n[0] * n[2] - s * n[1], R[7] = t * n[1] * n[2] + s * n[0], R[8] = c + t * n[2] * n[2];
    for (k = 0; k < 3; k++) q[k] = (frm_real)(sin(0.5 * a) * n[k]);
    q[3] = (frm_real)cos(0.5 * a);
}

/* Patch test with the option on, unstructured meshes (nodes moved by up to 0.05 m of 0.5 m
   cells), every law and every mode: frames placed on a homogeneous deformation F = R U (x_i
   = F X_i + b, every frame turned by R, U symmetric) give every sample exactly F (the
   frames' interpolation reproduces it), so J_bar = J, F_bar = F and the model must carry
   the homogeneous stress P(F): its forces and elastic energy equal the model's without the
   option, whose per-sample path is the plain law (an independent evaluation), to
   round-off (1e-10 of the largest force in double; float 1e-4: its 1e-7 rounding of
   forces that cancel between samples). */
static void test_vol_patch(void)
{
    static const double U[9] = {1.08, 0.03, -0.02, 0.03, 0.93, 0.05, -0.02, 0.05, 1.04}, axis[3] = {0.48, 0.6, 0.64};
    double R[9], F[9], tol = IS_FLOAT ? 1e-4 : 1e-10;
    int mode, law, i, r, c;
    frm_real qr[4];
    vol_rotation(axis, 0.4, R, qr);
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++) F[3 * r + c] = R[3 * r] * U[c] + R[3 * r + 1] * U[3 + c] + R[3 * r + 2] * U[6 + c];
    for (mode = FRM_VOLUMETRIC_CELLS; mode <= FRM_VOLUMETRIC_PATCHES; mode++)
        for (law = 0; law < FRM_LAW_COUNT; law++) {
            frm_sampling s;
            frm_model *m[2];
            frm_real *x0, *pos, *quat, *f[2];
            frm_energies en[2];
            double worst = 0, fmaxv = 0;
            int n, on;
            REQUIRE(vol_body(mode, 0.05, &s, &x0, &n) == FRM_OK);
            pos = alloc_reals(3 * n), quat = alloc_reals(4 * n);
            for (i = 0; i < n; i++) {
                for (r = 0; r < 3; r++)
                    pos[3 * i + r] = (frm_real)(F[3 * r] * x0[3 * i] + F[3 * r + 1] * x0[3 * i + 1] + F[3 * r + 2] * x0[3 * i + 2] + 0.3 * (r + 1));
                memcpy(quat + 4 * i, qr, sizeof qr);
            }
            for (on = 0; on < 2; on++) {
                frm_desc d = frm_model_default_desc();
                const frm_real *g;
                frm_sampling_apply(&s, &d);
                d.material = law_material(law);
                d.volumetric = on ? (frm_volumetric)mode : FRM_VOLUMETRIC_NONE;
                d.volumetric_patch_size = VOL_PATCH;
                d.gravity[2] = 0;
                REQUIRE(frm_model_create(&d, &m[on]) == FRM_OK);
                REQUIRE(frm_model_set_poses(m[on], pos, quat) == FRM_OK);
                REQUIRE(frm_model_forces(m[on], &g) == FRM_OK);
                f[on] = alloc_reals(6 * n);
                memcpy(f[on], g, sizeof(frm_real) * 6 * n);
                REQUIRE(frm_model_energy(m[on], &en[on]) == FRM_OK);
            }
            for (i = 0; i < 6 * n; i++) fmaxv = fmax(fmaxv, fabs((double)f[0][i]));
            for (i = 0; i < 6 * n; i++) worst = fmax(worst, fabs((double)f[1][i] - (double)f[0][i]) / fmaxv);
            printf("    %-6s %-20s homogeneous F: forces on vs off %.1e of max, energy %.1e relative\n",
                   vol_name(mode), frm__laws[law].name, worst,
                   fabs(en[1].elastic - en[0].elastic) / en[0].elastic);
            CHECK(fmaxv > 0);
            CHECK(worst < tol);
            CHECK_NEAR(en[0].elastic, en[1].elastic, tol * en[0].elastic);
            frm_model_destroy(m[0]);
            frm_model_destroy(m[1]);
            frm_sampling_free(&s);
            free(x0), free(pos), free(quat), free(f[0]), free(f[1]);
        }
}

/* Zero force under rigid motion with the option on, far from the origin too: the body's
   rest pose offset by 1e4 m (float 1e2 m: float keeps about 1e-5 m there), then turned by
   0.7 rad about an oblique axis and moved 10 m. Forces below 1e-6 (double) / 5e-3 (float)
   of the force a 1 % strain gives a sample face (E 0.01 h^2, h = 0.5 m): the rounding of
   the positions, 1e-12 m and 1e-5 m, over h. */
static void test_vol_rigid(void)
{
    static const double axis[3] = {0.36, -0.48, 0.8};
    double R[9], off = IS_FLOAT ? 1e2 : 1e4, scale = LAW_E * 0.01 * 0.25, tol = IS_FLOAT ? 5e-3 : 1e-6;
    int mode, law, i, r;
    frm_real q[4];
    vol_rotation(axis, 0.7, R, q);
    for (mode = FRM_VOLUMETRIC_CELLS; mode <= FRM_VOLUMETRIC_PATCHES; mode++)
        for (law = 0; law < FRM_LAW_COUNT; law++) {
            frm_sampling s;
            frm_model *m;
            frm_desc d = frm_model_default_desc();
            frm_real *x0, *pos, *quat, *moved, *svol;
            const frm_real *f;
            double worst = 0;
            int n, e;
            REQUIRE(vol_body(mode, 0.05, &s, &x0, &n) == FRM_OK);
            /* the same mesh far away: frames and samples moved (weights and gradients unchanged) */
            moved = alloc_reals(3 * s.sample_count);
            for (i = 0; i < 3 * s.sample_count; i++) moved[i] = (frm_real)((double)s.sample_positions[i] + off);
            for (i = 0; i < 3 * n; i++) s.frame_positions[i] = (frm_real)((double)s.frame_positions[i] + off);
            svol = s.sample_positions;
            s.sample_positions = moved;
            frm_sampling_apply(&s, &d);
            s.sample_positions = svol;
            d.material = law_material(law);
            d.volumetric = (frm_volumetric)mode;
            d.volumetric_patch_size = VOL_PATCH;
            d.gravity[2] = 0;
            REQUIRE(frm_model_create(&d, &m) == FRM_OK);
            pos = alloc_reals(3 * n), quat = alloc_reals(4 * n);
            for (i = 0; i < n; i++) {
                for (r = 0; r < 3; r++)
                    pos[3 * i + r] = (frm_real)(R[3 * r] * x0[3 * i] + R[3 * r + 1] * x0[3 * i + 1] + R[3 * r + 2] * x0[3 * i + 2] + off + 10);
                memcpy(quat + 4 * i, q, sizeof q);
            }
            REQUIRE(frm_model_set_poses(m, pos, quat) == FRM_OK);
            e = frm_model_forces(m, &f);
            CHECK_INT(FRM_OK, e);
            if (!e)
                for (i = 0; i < 6 * n; i++) worst = fmax(worst, fabs((double)f[i]) / (i % 6 < 3 ? scale : scale * 0.5));
            printf("    %-6s %-20s rigid motion at %.0e m: |f| %.1e of a 1 %% strain's\n",
                   vol_name(mode), frm__laws[law].name, off, worst);
            CHECK(worst < tol);
            frm_model_destroy(m);
            frm_sampling_free(&s);
            free(x0), free(pos), free(quat), free(moved);
        }
}

/* Refusals: unknown mode, CELLS without sample_cells or with a negative index, a negative
   or non-finite stabilisation, a PATCHES size out of 0..FRM_VOLUMETRIC_PATCH_MAX
   (FRM_ERR_VOLUMETRIC), assembled blocks with the option
   (FRM_ERR_STIFFNESS_MODE); the option's model is matrix-free (no block storage). */
static void test_vol_refusals(void)
{
    frm_sampling s;
    frm_desc d;
    frm_model *m = NULL;
    int *cells;
    REQUIRE(vol_body(FRM_VOLUMETRIC_CELLS, 0, &s, NULL, NULL) == FRM_OK);
    CHECK(s.cell_count == 2 && s.sample_cells && s.sample_cells[0] == 0 && s.sample_cells[s.sample_count - 1] == 1);
    cells = (int *)calloc((size_t)s.sample_count, sizeof(int));
    d = frm_model_default_desc();
    frm_sampling_apply(&s, &d);
    CHECK(d.sample_cells == s.sample_cells && d.volumetric == FRM_VOLUMETRIC_NONE);
    d.volumetric = FRM_VOLUMETRIC_COUNT;
    CHECK_INT(FRM_ERR_VOLUMETRIC, frm_model_create(&d, &m));
    d.volumetric = FRM_VOLUMETRIC_CELLS;
    d.sample_cells = NULL;
    CHECK_INT(FRM_ERR_VOLUMETRIC, frm_model_create(&d, &m));
    cells[3] = -1;
    d.sample_cells = cells;
    CHECK_INT(FRM_ERR_VOLUMETRIC, frm_model_create(&d, &m));
    cells[3] = 0;
    d.volumetric_stabilization = -1;
    CHECK_INT(FRM_ERR_VOLUMETRIC, frm_model_create(&d, &m));
    d.volumetric_stabilization = (frm_real)NAN;
    CHECK_INT(FRM_ERR_VOLUMETRIC, frm_model_create(&d, &m));
    d.volumetric_stabilization = 2;
    d.volumetric = FRM_VOLUMETRIC_PATCHES; /* the patch size: 0 (default) to FRM_VOLUMETRIC_PATCH_MAX */
    d.volumetric_patch_size = -1;
    CHECK_INT(FRM_ERR_VOLUMETRIC, frm_model_create(&d, &m));
    d.volumetric_patch_size = FRM_VOLUMETRIC_PATCH_MAX + 1;
    CHECK_INT(FRM_ERR_VOLUMETRIC, frm_model_create(&d, &m));
    d.volumetric_patch_size = FRM_VOLUMETRIC_PATCH_MAX;
    d.sample_cells = NULL; /* not needed */
    REQUIRE(frm_model_create(&d, &m) == FRM_OK);
    CHECK_INT(1, m->vol_groups); /* 16 samples, patches up to 64: one */
    frm_model_destroy(m);
    m = NULL;
    d.volumetric_patch_size = 0;
    d.stiffness_mode = FRM_STIFFNESS_BLOCKS;
    CHECK_INT(FRM_ERR_STIFFNESS_MODE, frm_model_create(&d, &m));
    d.volumetric = FRM_VOLUMETRIC_CELLS;
    d.sample_cells = cells;
    CHECK(m == NULL);
    d.stiffness_mode = FRM_STIFFNESS_AUTO;
    REQUIRE(frm_model_create(&d, &m) == FRM_OK); /* one cell: every sample averages with all */
    CHECK_INT(FRM_ERR_STIFFNESS_MODE, frm_model_set_stiffness_mode(m, FRM_STIFFNESS_BLOCKS));
    CHECK_INT(FRM_ERR_STIFFNESS_MODE, frm_model_assemble_stiffness(m));
    frm_model_destroy(m);
    free(cells);
    frm_sampling_free(&s);
}

/* A tetrahedral mesh that does not show its grid: the beam's tetrahedra in a shuffled order
   (Fisher-Yates, fixed seed; vertices rotated within each tetrahedron, orientation kept)
   and the nodes off the boundary faces moved by up to 0.2 h along each axis. */
static void vol_unstructure(tetmesh *t, double L, double h)
{
    unsigned seed = 2468u;
    int i, r;
    for (i = t->tet_count - 1; i > 0; i--) {
        int j = (int)((law_rand(&seed) * 0.5 + 0.5) * (i + 1)), tmp[4];
        if (j > i) j = i;
        if (j < 0) j = 0;
        memcpy(tmp, t->tets + 4 * i, sizeof tmp);
        memcpy(t->tets + 4 * i, t->tets + 4 * j, sizeof tmp);
        memcpy(t->tets + 4 * j, tmp, sizeof tmp);
    }
    for (i = 0; i < t->tet_count; i++) /* an even permutation: (a b c d) -> (b c a d) */
        if (i % 2) {
            int a = t->tets[4 * i];
            t->tets[4 * i] = t->tets[4 * i + 1], t->tets[4 * i + 1] = t->tets[4 * i + 2], t->tets[4 * i + 2] = a;
        }
    for (i = 0; i < t->node_count; i++) {
        double *x = t->nodes + 3 * i;
        int inside[3];
        inside[0] = x[0] > 1e-9 && x[0] < L - 1e-9;
        inside[1] = fabs(x[1]) < 0.05 - 1e-9;
        inside[2] = fabs(x[2]) < 0.05 - 1e-9;
        for (r = 0; r < 3; r++) {
            double e = 0.2 * h * law_rand(&seed);
            if (inside[r]) x[r] += e;
        }
    }
}

/* FRM_VOLUMETRIC_PATCHES' partition, on a mesh that does not show its grid (the 10 x 2 x 2
   beam's 200 tetrahedra shuffled and its inner nodes moved, vol_unstructure) with two
   materials (x < 0.25 m and beyond), for patch sizes k = 0 (the default, 6), 1, 4, 8 and
   64: every sample is in exactly one patch (one averaging entry each, and each entry in
   its patch's list once), every patch is non-empty, of one material and connected
   through shared frames, and holds from ceil(k / 2) samples (smaller patches were given
   away) to 2 k - 1 (a bound measured here, not a guarantee: k grown plus the samples of
   small neighbours it took); k = 1 gives every sample its own
   patch; the averaging weights of a patch sum to 1 (A 1 = 1). The same description
   gives the same patches. */
static void test_vol_patches_partition(void)
{
    static const int sizes[5] = {0, 1, 4, 8, 64};
    tetmesh t;
    frm_sampling s;
    frm_real *x;
    frm_material mats[2];
    int *smat, *seen, *queue, *reach, i, n, S, z;
    REQUIRE(tetmesh_beam(&t, 0.5, 0.1, 0.1, 10, 2, 2, TETMESH_SPLIT5) == TETMESH_OK);
    vol_unstructure(&t, 0.5, 0.05);
    n = t.node_count;
    x = alloc_reals(3 * n);
    for (i = 0; i < 3 * n; i++) x[i] = (frm_real)t.nodes[i];
    REQUIRE(frm_sampling_tets(&s, x, n, t.tets, t.tet_count, 1, NULL, NULL) == FRM_OK);
    S = s.sample_count;
    smat = (int *)calloc((size_t)S, sizeof(int)), seen = (int *)calloc((size_t)S, sizeof(int));
    queue = (int *)calloc((size_t)S, sizeof(int)), reach = (int *)calloc((size_t)S, sizeof(int));
    for (i = 0; i < S; i++) smat[i] = s.sample_positions[3 * i] > (frm_real)0.25;
    mats[0] = mats[1] = frm_model_default_desc().material;
    mats[1].young_modulus = 2 * mats[0].young_modulus;
    for (z = 0; z < 5; z++) {
        frm_desc d = frm_model_default_desc();
        frm_model *m = NULL, *m2 = NULL;
        int k = sizes[z] ? sizes[z] : FRM_VOLUMETRIC_PATCH_SIZE, G, g, e, lo = S, hi = 0, ok = 1, wsum_ok = 1;
        frm_sampling_apply(&s, &d);
        d.materials = mats, d.material_count = 2, d.sample_materials = smat;
        d.volumetric = FRM_VOLUMETRIC_PATCHES;
        d.volumetric_patch_size = sizes[z];
        REQUIRE(frm_model_create(&d, &m) == FRM_OK);
        REQUIRE(frm_model_create(&d, &m2) == FRM_OK);
        G = m->vol_groups;
        CHECK(m2->vol_groups == G && memcmp(m->ve_group, m2->ve_group, sizeof(int) * (size_t)S) == 0);
        memset(seen, 0, sizeof(int) * (size_t)S);
        for (i = 0; i < S; i++) ok &= m->ve_start[i] == i && m->ve_sample[i] == i && m->ve_group[i] >= 0 && m->ve_group[i] < G;
        CHECK(ok);
        REQUIRE(m->vg_start[0] == 0 && m->vg_start[G] == S);
        for (e = 0; e < S; e++) seen[m->ve_sample[m->vg_entry[e]]]++;
        for (i = 0; i < S; i++) ok &= seen[i] == 1;
        CHECK(ok);
        for (g = 0; g < G; g++) {
            int size = m->vg_start[g + 1] - m->vg_start[g], first = m->ve_sample[m->vg_entry[m->vg_start[g]]];
            int head = 0, tail = 0, found = 1, a, p, q, r;
            double w = 0;
            if (size < lo) lo = size;
            if (size > hi) hi = size;
            for (e = m->vg_start[g]; e < m->vg_start[g + 1]; e++) {
                ok &= m->ve_group[m->vg_entry[e]] == g && smat[m->ve_sample[m->vg_entry[e]]] == smat[first];
                w += (double)m->ve_to[m->vg_entry[e]];
            }
            wsum_ok &= fabs(w - 1) < (IS_FLOAT ? 1e-5 : 1e-12);
            /* connected: a breadth-first search from the first sample over samples of the
               patch that share a frame */
            for (i = 0; i < S; i++) reach[i] = 0;
            queue[tail++] = first, reach[first] = 1;
            while (head < tail) {
                a = queue[head++];
                for (p = s.neighbor_start[a]; p < s.neighbor_start[a + 1]; p++)
                    for (i = 0; i < S; i++)
                        if (!reach[i] && m->ve_group[i] == g)
                            for (q = s.neighbor_start[i]; q < s.neighbor_start[i + 1]; q++)
                                if (s.neighbor_frames[q] == s.neighbor_frames[p] && !reach[i]) reach[i] = 1, queue[tail++] = i;
            }
            for (r = 0; r < S; r++) found &= (m->ve_group[r] == g) == (reach[r] == 1);
            ok &= found && tail == size && size > 0;
        }
        printf("    k = %2d: %d patches of %d samples, sizes %d to %d (mean %.2f)\n", k, G, S, lo, hi, (double)S / G);
        CHECK(ok);
        CHECK(wsum_ok);
        CHECK(lo >= (k + 1) / 2);
        CHECK(hi <= 2 * k - 1 || k == 1);
        if (k == 1) CHECK_INT(S, G);
        frm_model_destroy(m);
        frm_model_destroy(m2);
    }
    frm_sampling_free(&s);
    tetmesh_free(&t);
    free(x), free(smat), free(seen), free(queue), free(reach);
}

/* The tip sag of the bench's Poisson beam shortened to L = 0.5 m (0.1 x 0.1 m section,
   10 x 2 x 2 cubic cells, E = 1 MPa, own weight scaled for about 1 mm of sag, clamped at x = 0),
   hexahedral frames (8 sub-cell samples a cell) or tetrahedral frames (the 5-tetrahedra
   split, one sample each), relative to Timoshenko's (shear included; REFERENCES R1's
   formula); the solve's code, Newton and CG iterations. vol: 0 none, 1 CELLS (hexahedra) or
   FRAMES (tetrahedra), 2 PATCHES (default size), 3 tetrahedra with CELLS over each grid
   cell's 5 (grid order only); unstructured: the tetrahedral mesh through vol_unstructure. */
static double vol_beam_error_mesh(int hex, int vol, double nu, int unstructured, int *err, int *newton, int *cg)
{
    frm_sampling s;
    frm_desc d = frm_model_default_desc();
    frm_model *m = NULL;
    frm_real *x;
    double L = 0.5, a = 0.1, E = 1e6, rho = 1000, g = 0.01 / 1.5e5 * E, tip = 0;
    double A = a * a, I = a * a * a * a / 12, G = E / (2 * (1 + nu)), kap = 10 * (1 + nu) / (12 + 11 * nu), q = rho * g * A;
    double ref = q * L * L * L * L / (8 * E * I) + q * L * L / (2 * kap * G * A);
    int i, n, c = 0;
    *newton = *cg = 0;
    if (hex) {
        hexmesh h;
        double lo[3] = {0, -0.05, -0.05}, hi[3] = {0.5, 0.05, 0.05};
        if (hexmesh_grid(&h, lo, hi, 10, 2, 2) != TETMESH_OK) return *err = FRM_ERR_ALLOC, NAN;
        n = h.node_count;
        x = alloc_reals(3 * n);
        for (i = 0; i < 3 * n; i++) x[i] = (frm_real)h.nodes[i];
        *err = frm_sampling_hexes(&s, x, n, h.hexes, h.hex_count, 2, FRM_QUADRATURE_SUBCELL, NULL);
        hexmesh_free(&h);
    } else {
        tetmesh t;
        if (tetmesh_beam(&t, 0.5, 0.1, 0.1, 10, 2, 2, TETMESH_SPLIT5) != TETMESH_OK) return *err = FRM_ERR_ALLOC, NAN;
        if (unstructured) vol_unstructure(&t, 0.5, 0.05);
        n = t.node_count;
        x = alloc_reals(3 * n);
        for (i = 0; i < 3 * n; i++) x[i] = (frm_real)t.nodes[i];
        for (i = 0; i < n; i++)
            if (fabs(t.nodes[3 * i]) < 1e-12) x[3 * i] = 0;
        *err = frm_sampling_tets(&s, x, n, t.tets, t.tet_count, 1, NULL, NULL);
        tetmesh_free(&t);
    }
    if (*err) return free(x), NAN;
    frm_sampling_apply(&s, &d);
    d.material.young_modulus = (frm_real)E;
    d.material.poisson_ratio = (frm_real)nu;
    d.material.density = (frm_real)rho;
    d.gravity[2] = (frm_real)-g;
    d.cg_max_iterations = 20000;
    d.volumetric = !vol       ? FRM_VOLUMETRIC_NONE
                   : vol == 2 ? FRM_VOLUMETRIC_PATCHES
                   : hex      ? FRM_VOLUMETRIC_CELLS
                              : FRM_VOLUMETRIC_FRAMES;
    d.parallel_min_pairs = 1 << 30;
    if (vol == 3) { /* the grid's cells: tetmesh_beam emits the 5 tetrahedra of a cell in a row */
        for (i = 0; i < s.sample_count; i++) s.sample_cells[i] = i / 5;
        d.volumetric = FRM_VOLUMETRIC_CELLS;
    }
    *err = frm_model_create(&d, &m);
    if (*err) return frm_sampling_free(&s), free(x), NAN;
    for (i = 0; i < n; i++)
        if (x[3 * i] == 0) frm_model_fix_frame(m, i);
    *err = frm_model_solve_static(m);
    *newton = frm_model_last_stats(m)->newton_iterations;
    *cg = frm_model_last_stats(m)->cg_iterations;
    for (i = 0; i < n; i++)
        if (fabs((double)x[3 * i] - L) < 1e-9) {
            tip -= (double)frm_model_positions(m)[3 * i + 2] - (double)x[3 * i + 2];
            c++;
        }
    frm_model_destroy(m);
    frm_sampling_free(&s);
    free(x);
    return tip / c / ref - 1;
}

static double vol_beam_error(int hex, int vol, double nu, int *err, int *newton, int *cg)
{
    return vol_beam_error_mesh(hex, vol, nu, 0, err, newton, cg);
}

/* Volumetric locking removed (the cheap version of the bench's Poisson rows, whose 1 m
   beam bench/bench.c measures at 2 x 2 and 3 x 3 cells across). Hexahedral frames with
   mean dilatation: converged at nu = 0.3, 0.49, 0.499 and the error within 3.5 points of
   nu = 0.3's (measured +1.2, -1.5, -1.8 %: on this short beam (L / a = 5) the clamp's
   restraint of the lateral contraction, which grows with nu, stiffens the 3D answer beyond
   Timoshenko's; the 1 m beam is within 0.1 point at 2 cells across, 1.2 at 3), where the
   plain model is 34 and 65 points off. Tetrahedral frames with nodal averaging: converged,
   and less locked than without (measured -18.8 % against -31.3 % at 0.499: the averaging
   over frames halves the locking of one-sample tetrahedral frames, it does not remove it,
   see LIMITS). */
static void test_vol_poisson_beam(void)
{
#ifdef TEST_QUICK
    static const double nus[2] = {0.3, 0.499};
    const int count = 2;
#else
    static const double nus[3] = {0.3, 0.49, 0.499};
    const int count = 3;
#endif
    double e0 = 0, e, off, on;
    int i, err, newton, cg, err2, n2, cg2;
    for (i = 0; i < count; i++) {
        e = vol_beam_error(1, 1, nus[i], &err, &newton, &cg);
        printf("    hex frames, mean dilatation, nu = %g: %+.2f %% (Newton %d, CG %d)\n", nus[i], 100 * e, newton, cg);
        CHECK_INT(FRM_OK, err);
        if (i == 0) e0 = e;
        else CHECK(fabs(e - e0) < 0.035);
    }
    off = vol_beam_error(1, 0, 0.499, &err, &newton, &cg);
    printf("    hex frames, plain, nu = 0.499: %+.2f %% (Newton %d, CG %d)\n", 100 * off, newton, cg);
    CHECK(off < -0.3); /* locked */
    on = vol_beam_error(0, 1, 0.499, &err, &newton, &cg);
    off = vol_beam_error(0, 0, 0.499, &err2, &n2, &cg2);
    printf("    tet frames, nu = 0.499: nodal averaging %+.2f %% (Newton %d, CG %d), plain %+.2f %% (Newton %d, CG %d)\n",
           100 * on, newton, cg, 100 * off, n2, cg2);
    CHECK_INT(FRM_OK, err);
    CHECK(fabs(on) < fabs(off) - 0.05);
}

/* FRM_VOLUMETRIC_PATCHES removes the volumetric locking of one-sample tetrahedral frames
   without cells from the user: the beam of vol_beam_error (10 x 2 x 2 cells of five
   tetrahedra), on the grid's mesh and on the same mesh shuffled and moved
   (vol_unstructure, where no grid structure is left to use), default patches. The
   yardstick is mean dilatation over the grid's own cells of 5 tetrahedra (the treatment
   that removes the locking where such cells exist): on this coarse short beam (2 cells
   across, L / a = 5, the clamp restraining the lateral contraction) it moves the tip by
   about 10 points between nu = 0.3 and 0.499 (measured +0.45, -9.48 %; the plain model 31
   points, -31.3 %), so: every solve converges, the patches' error at nu = 0.49 and 0.499
   is within the cells' shift plus 1 point of the same mesh's error at nu = 0.3 (measured
   with the default 12: grid +0.48, -7.26, -7.89 %, unstructured -0.40, -1.48, -1.85 %),
   and the plain model on the unstructured mesh moves by more than twice that (locked: the
   check can fail). */
static void test_vol_patches_beam(void)
{
#ifdef TEST_QUICK /* the unstructured mesh only */
    static const double nus[2] = {0.3, 0.499};
    const int count = 2, first_mesh = 1;
#else
    static const double nus[3] = {0.3, 0.49, 0.499};
    const int count = 3, first_mesh = 0;
#endif
    double e0 = 0, e, c0, c1, tol, off0, off;
    int i, err, newton, cg, un;
    c0 = vol_beam_error_mesh(0, 3, 0.3, 0, &err, &newton, &cg);
    CHECK_INT(FRM_OK, err);
    c1 = vol_beam_error_mesh(0, 3, 0.499, 0, &err, &newton, &cg);
    CHECK_INT(FRM_OK, err);
    tol = fabs(c1 - c0) + 0.01;
    printf("    tet frames, grid mesh, cells of 5: nu = 0.3 %+.2f %%, 0.499 %+.2f %% (Newton %d, CG %d): tolerance %.1f points\n",
           100 * c0, 100 * c1, newton, cg, 100 * tol);
    for (un = first_mesh; un < 2; un++)
        for (i = 0; i < count; i++) {
            e = vol_beam_error_mesh(0, 2, nus[i], un, &err, &newton, &cg);
            printf("    tet frames, %s mesh, patches, nu = %g: %+.2f %% (Newton %d, CG %d)\n", un ? "unstructured" : "grid",
                   nus[i], 100 * e, newton, cg);
            CHECK_INT(FRM_OK, err);
            if (i == 0) e0 = e;
            else CHECK(fabs(e - e0) < tol);
        }
    off0 = vol_beam_error_mesh(0, 0, 0.3, 1, &err, &newton, &cg);
    CHECK_INT(FRM_OK, err);
    off = vol_beam_error_mesh(0, 0, 0.499, 1, &err, &newton, &cg);
    CHECK_INT(FRM_OK, err);
    printf("    tet frames, unstructured mesh, plain: nu = 0.3 %+.2f %%, 0.499 %+.2f %% (Newton %d, CG %d)\n", 100 * off0,
           100 * off, newton, cg);
    CHECK(fabs(off - off0) > 2 * tol);
}

static const test_case cases[] = {
    TEST(test_garbage_descriptions),
    TEST(test_float_renames),
    TEST(test_view_passes),
    TEST(test_shape_refusals),
    TEST(test_svk_mirrored_compression),
    TEST(test_svk_mirrored_step),
    TEST(test_tet_beam_modes),
    TEST(test_hex_beam_modes),
    TEST(test_hex_one_cell_r1),
    TEST(test_hex_soft_cantilever_r2),
    TEST(test_law_derivatives),
    TEST(test_law_user_matches_neo_hookean),
    TEST(test_law_uniaxial_closed_forms),
    TEST(test_law_model_path),
    TEST(test_law_validation),
    TEST(test_integrator_choice),
    TEST(test_probe_kinds),
    TEST(test_probe_refusals),
    TEST(test_probe_many),
    TEST(test_modal_r3),
    TEST(test_modal_closed_forms),
    TEST(test_modal_r3_time_order),
    TEST(test_vol_derivatives),
    TEST(test_vol_patch),
    TEST(test_vol_rigid),
    TEST(test_vol_refusals),
    TEST(test_vol_patches_partition),
    TEST(test_vol_poisson_beam),
    TEST(test_vol_patches_beam),
};

int main(int argc, char **argv) { return TEST_MAIN(argc, argv, cases); }
