/* Tests of tensormass.h's precomputed quasi-static model and hybrid model (Cotin et al.
   sec. 4 and 6): superposition and reaction forces against direct static solves, save/load,
   refusals, and the hybrid against one tensor-mass model of the whole mesh, also after
   cuts. */
#define TENSORMASS_IMPLEMENTATION
#include "../tensormass.h"
#define TETMESH_IMPLEMENTATION
#include "../examples/tetmesh.h"
#include "test.h"
#include "fixtures.h"

#define IS_FLOAT (sizeof(tmass_real) == sizeof(float))
/* Agreement expected between two solves of the same linear problem: CG tolerances are
   1e-10 (precomputation) and 1e-12 (direct solves) in double; float solves stop near 1e-6
   and the stored compliance is rounded to 7 digits. */
#define SOLVE_TOL (IS_FLOAT ? 2e-3 : 1e-7)

static tmass_real *alloc_reals(int count)
{
    return (tmass_real *)calloc(count > 0 ? (size_t)count : 1, sizeof(tmass_real));
}

/* A beam 0.3 x 0.1 x 0.1 m of 6 x 2 x 2 cells (5 tets each), E = 50 kPa, fixed at x = 0. */
static void beam_mesh(tetmesh *mesh) { tetmesh_beam(mesh, 0.3, 0.1, 0.1, 6, 2, 2, TETMESH_SPLIT5); }

static tmass_desc beam_desc(const tetmesh *mesh, tmass_real *rest)
{
    tmass_desc d = tmass_default_desc();
    int i;
    for (i = 0; i < 3 * mesh->node_count; i++) rest[i] = (tmass_real)mesh->nodes[i];
    d.rest_positions = rest;
    d.node_count = mesh->node_count;
    d.tets = mesh->tets;
    d.tet_count = mesh->tet_count;
    d.young_modulus = (tmass_real)5e4;
    d.poisson_ratio = (tmass_real)0.3;
    d.density = (tmass_real)1000;
    d.cg_tolerance = (tmass_real)(IS_FLOAT ? 1e-6 : 1e-12);
    d.cg_max_iterations = 20000;
    return d;
}

static tmass_model *beam_model(const tetmesh *mesh, tmass_real *rest)
{
    tmass_desc d = beam_desc(mesh, rest);
    tmass_model *m = NULL;
    int i;
    if (tmass_create(&d, &m)) return NULL;
    for (i = 0; i < mesh->node_count; i++)
        if (mesh->nodes[3 * i] == 0.0) tmass_fix_node(m, i);
    return m;
}

static double max_abs(const tmass_real *a, int n)
{
    double s = 0.0;
    int i;
    for (i = 0; i < n; i++)
        if (fabs((double)a[i]) > s) s = fabs((double)a[i]);
    return s;
}

/* Three nodes of the free end's top face. */
static void contact_nodes(const tetmesh *mesh, int nodes[3])
{
    double p0[3] = {0.3, 0.05, 0.05}, p1[3] = {0.3, -0.05, 0.05}, p2[3] = {0.25, 0.0, 0.05};
    nodes[0] = tetmesh_nearest_node(mesh, p0);
    nodes[1] = tetmesh_nearest_node(mesh, p1);
    nodes[2] = tetmesh_nearest_node(mesh, p2);
}

/* ---- quasi-static model ------------------------------------------------------------ */

/* Superposition: several simultaneous imposed displacements give the displacements of a
   direct static solve with those nodes pinned, at every node; the contact forces equal
   the force needed to hold those nodes in the direct solve (minus its internal force,
   gravity and external load there). */
static void test_qs_matches_direct_solve(void)
{
    tetmesh mesh;
    tmass_real *rest, u[9] = {0.002f, 0.0f, -0.01f, -0.001f, 0.003f, -0.008f, 0.0f, 0.0f, 0.004f};
    tmass_real forces[9], ext[3] = {0.0f, 0.5f, 0.0f};
    tmass_model *m, *direct;
    tmass_qs *qs;
    tmass_qs_desc qd = tmass_qs_default_desc();
    int nodes[3], i, r, pass;
    beam_mesh(&mesh);
    rest = alloc_reals(3 * mesh.node_count);
    contact_nodes(&mesh, nodes);
    for (pass = 0; pass < 2; pass++) { /* output at every node, then at the surface only */
        double worst = 0.0, scale, fworst = 0.0, fscale;
        m = beam_model(&mesh, rest);
        REQUIRE(m != NULL);
        tmass_set_external_force(m, 5, ext); /* a load in the preload too */
        qd.all_nodes = pass == 0;
        CHECK_INT(TMASS_OK, tmass_qs_create(m, &qd, &qs));
        REQUIRE(qs != NULL);
        CHECK_INT(TMASS_OK, tmass_qs_update(qs, nodes, u, 3, forces));
        direct = beam_model(&mesh, rest);
        tmass_set_external_force(direct, 5, ext);
        for (i = 0; i < 3; i++) tmass_set_displacement(direct, nodes[i], u + 3 * i);
        CHECK_INT(TMASS_OK, tmass_solve_static(direct));
        scale = max_abs(u, 9);
        for (i = 0; i < mesh.node_count; i++) {
            int out = pass == 0 || qs->row_of_node[i] >= 0;
            if (!out) continue;
            for (r = 0; r < 3; r++) {
                double d = fabs((double)tmass_qs_displacements(qs)[3 * i + r] -
                                ((double)tmass_positions(direct)[3 * i + r] - mesh.nodes[3 * i + r]));
                if (d > worst) worst = d;
            }
        }
        {
            const tmass_real *f = tmass_forces(direct);
            fscale = max_abs(forces, 9);
            for (i = 0; i < 3; i++)
                for (r = 0; r < 3; r++) {
                    int v = nodes[i];
                    double hold = -((double)f[3 * v + r] + (v == 5 ? ext[r] : 0) +
                                    (double)tmass_masses(direct)[v] * (r == 2 ? -9.81 : 0.0));
                    if (fabs(hold - forces[3 * i + r]) > fworst) fworst = fabs(hold - forces[3 * i + r]);
                }
        }
        printf("    %s: max |u_qs - u_direct| / max |u_imposed| = %.2e, contact forces %.2e (max %.3g N)\n",
               pass == 0 ? "all nodes" : "surface nodes", worst / scale, fworst / fscale, fscale);
        CHECK(worst <= SOLVE_TOL * scale);
        CHECK(fworst <= 10 * SOLVE_TOL * fscale);
        /* the imposed displacements are met by a dense solve, not an iteration: to the
           round-off of a 9 x 9 Cholesky (condition ~1e3) and of the superposition */
        for (i = 0; i < 9; i++)
            CHECK_NEAR(u[i], tmass_qs_displacements(qs)[3 * nodes[i / 3] + i % 3],
                       (IS_FLOAT ? 1e-4 : 1e-9) * scale);
        tmass_qs_destroy(qs);
        tmass_destroy(direct);
        tmass_destroy(m);
    }
    free(rest);
    tetmesh_free(&mesh);
}

/* The precomputed compliance is symmetric (Maxwell-Betti reciprocity), a property of a
   correct K^-1 that no single column solve enforces. */
static void test_qs_compliance_symmetric(void)
{
    tetmesh mesh;
    tmass_real *rest;
    tmass_model *m;
    tmass_qs *qs;
    tmass_qs_desc qd = tmass_qs_default_desc();
    int i, j, p3;
    double worst = 0.0, scale = 0.0;
    beam_mesh(&mesh);
    rest = alloc_reals(3 * mesh.node_count);
    m = beam_model(&mesh, rest);
    REQUIRE(m != NULL);
    REQUIRE(tmass_qs_create(m, &qd, &qs) == TMASS_OK);
    p3 = 3 * qs->pre_count;
    for (i = 0; i < p3; i++)
        for (j = 0; j < p3; j++) {
            double a = tmass__qs_entry(qs, i, j), b = tmass__qs_entry(qs, j, i);
            if (fabs(a - b) > worst) worst = fabs(a - b);
            if (fabs(a) > scale) scale = fabs(a);
        }
    printf("    %d precomputed nodes, max |C_ij - C_ji| / max |C| = %.2e, %lu bytes\n", qs->pre_count,
           worst / scale, (unsigned long)tmass_qs_memory_bytes(qs));
    CHECK(worst <= SOLVE_TOL * scale);
    tmass_qs_destroy(qs);
    tmass_destroy(m);
    free(rest);
    tetmesh_free(&mesh);
}

static int count_progress(int done, int total, void *user)
{
    int *c = (int *)user; /* calls, total, cancel after this many calls, last done */
    c[0]++;
    c[1] = total;
    CHECK(done > c[3] && done <= total); /* increasing, within the total */
    c[3] = done;
    return c[2] > 0 && c[0] >= c[2];
}

/* Progress reports the solves done up to the total (the preload, then blocks of 8); a
   non-zero return cancels cleanly. */
static void test_qs_progress_and_cancel(void)
{
    tetmesh mesh;
    tmass_real *rest;
    tmass_model *m;
    tmass_qs *qs = NULL;
    tmass_qs_desc qd = tmass_qs_default_desc();
    int calls[4] = {0, 0, 0, 0}, n;
    beam_mesh(&mesh);
    rest = alloc_reals(3 * mesh.node_count);
    m = beam_model(&mesh, rest);
    REQUIRE(m != NULL);
    qd.progress = count_progress;
    qd.progress_user = calls;
    CHECK_INT(TMASS_OK, tmass_qs_create(m, &qd, &qs));
    tmass_qs_nodes(qs, &n);
    CHECK_INT(1 + (3 * n + 7) / 8, calls[0]);
    CHECK_INT(3 * n + 1, calls[1]);
    CHECK_INT(3 * n + 1, calls[3]);
    tmass_qs_destroy(qs);
    calls[0] = calls[3] = 0;
    calls[2] = 5;
    qs = (tmass_qs *)&calls; /* must come back NULL */
    CHECK_INT(TMASS_ERR_CANCELLED, tmass_qs_create(m, &qd, &qs));
    CHECK(qs == NULL);
    CHECK_INT(5, calls[0]);
    tmass_destroy(m);
    free(rest);
    tetmesh_free(&mesh);
}

/* Save and load reproduce the precomputation bit for bit; corrupted, truncated, foreign
   and mismatched files are refused with their codes. */
static void test_qs_save_load(void)
{
    tetmesh mesh;
    tmass_real *rest, u[3] = {0.0f, 0.0f, -0.01f};
    tmass_model *m, *other;
    tmass_qs *qs, *back;
    tmass_qs_desc qd = tmass_qs_default_desc();
    char path[512], bad_path[512];
    unsigned char *buf, *copy;
    size_t size, cut;
    const char *dir = getenv("TEST_TMPDIR");
    int nodes[3], k;
    FILE *f;
    beam_mesh(&mesh);
    rest = alloc_reals(3 * mesh.node_count);
    contact_nodes(&mesh, nodes);
    m = beam_model(&mesh, rest);
    REQUIRE(m != NULL);
    REQUIRE(tmass_qs_create(m, &qd, &qs) == TMASS_OK);
    snprintf(path, sizeof path, "%s/qs_roundtrip.bin", dir ? dir : "build");
    snprintf(bad_path, sizeof bad_path, "%s/qs_bad.bin", dir ? dir : "build");
    CHECK_INT(TMASS_OK, tmass_qs_save(qs, path));
    CHECK_INT(TMASS_OK, tmass_qs_load(m, &qd, path, &back));
    REQUIRE(back != NULL);
    CHECK(memcmp(qs->compliance, back->compliance, sizeof(tmass_real) * 9 * (size_t)qs->pre_count * qs->out_count) == 0);
    CHECK(memcmp(qs->preload, back->preload, sizeof(tmass_real) * 3 * (size_t)qs->node_count) == 0);
    tmass_qs_update(qs, nodes, u, 1, NULL);
    tmass_qs_update(back, nodes, u, 1, NULL);
    CHECK(memcmp(tmass_qs_positions(qs), tmass_qs_positions(back), sizeof(tmass_real) * 3 * (size_t)mesh.node_count) == 0);
    tmass_qs_destroy(back);

    CHECK_INT(TMASS_OK, tmass_qs_save_memory(qs, NULL, 0, &size));
    buf = (unsigned char *)malloc(size);
    copy = (unsigned char *)malloc(size);
    CHECK_INT(TMASS_ERR_ARG, tmass_qs_save_memory(qs, buf, size - 1, &size));
    CHECK_INT(TMASS_OK, tmass_qs_save_memory(qs, buf, size, &size));
    CHECK_INT(TMASS_OK, tmass_qs_load_memory(m, &qd, buf, size, &back));
    tmass_qs_destroy(back);
    /* truncated anywhere */
    for (cut = 0; cut < size; cut += 1 + size / 23) {
        back = (tmass_qs *)&cut;
        k = tmass_qs_load_memory(m, &qd, buf, cut, &back);
        CHECK(k == TMASS_ERR_FILE_TRUNCATED || (cut < 8 && k == TMASS_ERR_FILE_TRUNCATED));
        CHECK(back == NULL);
    }
    CHECK_INT(TMASS_ERR_FILE_TRUNCATED, tmass_qs_load_memory(m, &qd, buf, size - 1, &back));
    /* wrong magic, version, byte order, real size */
    memcpy(copy, buf, size); copy[0] = 'X';
    CHECK_INT(TMASS_ERR_FILE_FORMAT, tmass_qs_load_memory(m, &qd, copy, size, &back));
    memcpy(copy, buf, size); copy[8] = 99;
    CHECK_INT(TMASS_ERR_FILE_VERSION, tmass_qs_load_memory(m, &qd, copy, size, &back));
    memcpy(copy, buf, size); copy[12] ^= 0xFF;
    CHECK_INT(TMASS_ERR_FILE_VERSION, tmass_qs_load_memory(m, &qd, copy, size, &back));
    memcpy(copy, buf, size); copy[16] = (unsigned char)(12 - sizeof(tmass_real)); /* the other real type */
    CHECK_INT(TMASS_ERR_FILE_VERSION, tmass_qs_load_memory(m, &qd, copy, size, &back));
    /* a flipped payload byte fails the checksum */
    memcpy(copy, buf, size); copy[TMASS__QS_HEADER_BYTES + 17] ^= 0x10;
    CHECK_INT(TMASS_ERR_FILE_FORMAT, tmass_qs_load_memory(m, &qd, copy, size, &back));
    /* a flipped fingerprint or another mesh state is a mismatch */
    memcpy(copy, buf, size); copy[40] ^= 1;
    CHECK_INT(TMASS_ERR_FILE_MISMATCH, tmass_qs_load_memory(m, &qd, copy, size, &back));
    other = beam_model(&mesh, rest);
    tmass_fix_node(other, nodes[0]); /* other boundary conditions */
    CHECK_INT(TMASS_ERR_FILE_MISMATCH, tmass_qs_load_memory(other, &qd, buf, size, &back));
    tmass_destroy(other);
    qd.all_nodes = 1; /* other settings */
    CHECK_INT(TMASS_ERR_FILE_MISMATCH, tmass_qs_load_memory(m, &qd, buf, size, &back));
    qd.all_nodes = 0;
    /* files: missing, and a truncated one on disk */
    CHECK_INT(TMASS_ERR_FILE_IO, tmass_qs_load(m, &qd, "build/no/such/file.bin", &back));
    f = fopen(bad_path, "wb");
    REQUIRE(f != NULL);
    fwrite(buf, 1, size / 2, f);
    fclose(f);
    CHECK_INT(TMASS_ERR_FILE_TRUNCATED, tmass_qs_load(m, &qd, bad_path, &back));
    CHECK_INT(TMASS_ERR_FILE_IO, tmass_qs_save(qs, "build/no/such/dir/x.bin"));
    free(buf);
    free(copy);
    tmass_qs_destroy(qs);
    tmass_destroy(m);
    free(rest);
    tetmesh_free(&mesh);
}

/* Refusals and validation of the quasi-static model; no allocation per update. */
static void test_qs_validation(void)
{
    tetmesh mesh;
    tmass_real *rest, u[6] = {0, 0, -0.01f, 0, 0, -0.01f}, nan3[3] = {0, (tmass_real)NAN, 0};
    tmass_model *m;
    tmass_qs *qs;
    tmass_qs_desc qd = tmass_qs_default_desc(), bad;
    counting_allocator c = {0, 0, 0, 0};
    int nodes[3], twice[2], fixed_node = 0, interior, list[1], allocs, i;
    double centre[3] = {0.15, 0.0, 0.0};
    beam_mesh(&mesh);
    rest = alloc_reals(3 * mesh.node_count);
    contact_nodes(&mesh, nodes);
    interior = tetmesh_nearest_node(&mesh, centre);
    m = beam_model(&mesh, rest);
    REQUIRE(m != NULL);
    bad = qd; bad.internal_cookie = 0;
    CHECK_INT(TMASS_ERR_DESC, tmass_qs_create(m, &bad, &qs));
    bad = qd; bad.max_contacts = 0;
    CHECK_INT(TMASS_ERR_ARG, tmass_qs_create(m, &bad, &qs));
    bad = qd; bad.cg_tolerance = 0;
    CHECK_INT(TMASS_ERR_SOLVER, tmass_qs_create(m, &bad, &qs));
    bad = qd; list[0] = fixed_node; bad.nodes = list; bad.node_count = 1;
    CHECK_INT(TMASS_ERR_NODE_PINNED, tmass_qs_create(m, &bad, &qs));
    list[0] = mesh.node_count;
    CHECK_INT(TMASS_ERR_NODE_RANGE, tmass_qs_create(m, &bad, &qs));
    CHECK_INT(TMASS_ERR_ARG, tmass_qs_create(NULL, &qd, &qs));
    qd.allocator.alloc = count_alloc;
    qd.allocator.free = count_free;
    qd.allocator.user = &c;
    qd.max_contacts = 2;
    REQUIRE(tmass_qs_create(m, &qd, &qs) == TMASS_OK);
    CHECK(qs->row_of_node[interior] < 0); /* the centre is not a surface node */
    allocs = c.allocs;
    CHECK_INT(TMASS_ERR_NOT_PRECOMPUTED, tmass_qs_update(qs, &interior, u, 1, NULL));
    CHECK_INT(TMASS_ERR_NOT_PRECOMPUTED, tmass_qs_update(qs, &fixed_node, u, 1, NULL));
    twice[0] = twice[1] = nodes[0];
    CHECK_INT(TMASS_ERR_CONTACTS, tmass_qs_update(qs, twice, u, 2, NULL));
    CHECK_INT(TMASS_ERR_CONTACTS, tmass_qs_update(qs, nodes, u, 3, NULL)); /* max_contacts 2 */
    CHECK_INT(TMASS_ERR_ARG, tmass_qs_update(qs, nodes, nan3, 1, NULL));
    CHECK_INT(TMASS_ERR_NODE_RANGE, tmass_qs_update(qs, list, u, 1, NULL));
    CHECK_INT(TMASS_ERR_PRECOMPUTED, tmass_qs_remove_tets(qs, nodes, 1));
    for (i = 0; i < 100; i++) CHECK_INT(TMASS_OK, tmass_qs_update(qs, nodes, u, 2, NULL));
    CHECK_INT(TMASS_OK, tmass_qs_update(qs, nodes, u, 0, NULL)); /* back to the preload */
    CHECK(memcmp(qs->disp, qs->preload, sizeof(tmass_real) * 3 * (size_t)mesh.node_count) == 0);
    CHECK_INT(allocs, c.allocs);
    tmass_qs_destroy(qs);
    CHECK_INT(c.allocs, c.frees);
    tmass_destroy(m);
    {
        /* the spring model has no linear compliance */
        tmass_desc d = beam_desc(&mesh, rest);
        d.kind = TMASS_MASS_SPRING;
        REQUIRE(tmass_create(&d, &m) == TMASS_OK);
        CHECK_INT(TMASS_ERR_MODEL_KIND, tmass_qs_create(m, &qd, &qs));
        tmass_destroy(m);
    }
    free(rest);
    tetmesh_free(&mesh);
}

/* ---- hybrid model ------------------------------------------------------------------ */

/* The beam's free half is dynamic (where cutting happens), the clamped half precomputed. */
static tmass_hybrid *make_hybrid(const tetmesh *mesh, tmass_real *rest, unsigned char *dynamic,
                                 int *fixed, int *fixed_count)
{
    tmass_hybrid_desc hd = tmass_hybrid_default_desc();
    tmass_hybrid *h = NULL;
    int t, i, err;
    hd.model = beam_desc(mesh, rest);
    for (t = 0; t < mesh->tet_count; t++) {
        double cx = 0;
        for (i = 0; i < 4; i++) cx += 0.25 * mesh->nodes[3 * mesh->tets[4 * t + i]];
        dynamic[t] = cx > 0.15;
    }
    *fixed_count = 0;
    for (i = 0; i < mesh->node_count; i++)
        if (mesh->nodes[3 * i] == 0.0) fixed[(*fixed_count)++] = i;
    hd.tet_dynamic = dynamic;
    hd.fixed_nodes = fixed;
    hd.fixed_count = *fixed_count;
    hd.precompute.max_contacts = 4;
    hd.precompute.all_nodes = 1; /* compare interior nodes of the precomputed part too */
    err = tmass_hybrid_create(&hd, &h);
    if (err) fprintf(stderr, "tmass_hybrid_create: %s\n", tmass_error_string(err));
    return h;
}

static double compare_positions(const tmass_real *a, const tetmesh *mesh, const tmass_model *whole)
{
    double worst = 0.0;
    int i;
    for (i = 0; i < 3 * mesh->node_count; i++) {
        double d = fabs((double)a[i] - (double)tmass_positions(whole)[i]);
        if (d > worst) worst = d;
    }
    return worst;
}

/* The paper's check: with the same Lame coefficients everywhere, the hybrid's steady state
   under gravity equals one tensor-mass model of the whole mesh; also with contacts on
   either part, and after cutting tetrahedra of the dynamic part at the interface
   (the whole model gets the same cuts). */
static void test_hybrid_equals_whole(void)
{
    tetmesh mesh;
    tmass_real *rest, u_qs[3] = {0.0f, 0.002f, 0.004f}, u_dyn[3] = {0.0f, 0.0f, -0.006f};
    unsigned char *dynamic;
    int *fixed, nfixed, i, stage, cut[64], ncut = 0, t, removed, qs_node, dyn_node, c0;
    double p_qs[3] = {0.1, 0.05, 0.05}, p_dyn[3] = {0.3, 0.05, 0.05};
    tmass_hybrid *h;
    tmass_model *whole;
    beam_mesh(&mesh);
    rest = alloc_reals(3 * mesh.node_count);
    dynamic = (unsigned char *)calloc((size_t)mesh.tet_count, 1);
    fixed = (int *)calloc((size_t)mesh.node_count, sizeof(int));
    h = make_hybrid(&mesh, rest, dynamic, fixed, &nfixed);
    REQUIRE(h != NULL);
    whole = beam_model(&mesh, rest);
    qs_node = tetmesh_nearest_node(&mesh, p_qs);
    dyn_node = tetmesh_nearest_node(&mesh, p_dyn);
    c0 = tmass_hybrid_connection_count(h);
    /* dynamic tets touching the interface plane x = 0.15, top half: a cut at the joint */
    for (t = 0; t < mesh.tet_count; t++) {
        double cx = 0, cz = 0;
        for (i = 0; i < 4; i++) {
            cx += 0.25 * mesh.nodes[3 * mesh.tets[4 * t + i]];
            cz += 0.25 * mesh.nodes[3 * mesh.tets[4 * t + i] + 2];
        }
        if (dynamic[t] && cx < 0.2 && cz > 0.0 && ncut < 64) cut[ncut++] = t;
    }
    for (stage = 0; stage < 4; stage++) {
        double worst, scale = 0.0;
        if (stage == 1) { /* a contact on the precomputed part */
            CHECK_INT(TMASS_OK, tmass_hybrid_set_displacement(h, qs_node, u_qs));
            tmass_set_displacement(whole, qs_node, u_qs);
        }
        if (stage == 2) { /* and one on the dynamic part */
            CHECK_INT(TMASS_OK, tmass_hybrid_set_displacement(h, dyn_node, u_dyn));
            tmass_set_displacement(whole, dyn_node, u_dyn);
        }
        if (stage == 3) { /* cut at the interface */
            CHECK_INT(TMASS_OK, tmass_hybrid_remove_tets(h, cut, ncut, &removed));
            CHECK_INT(ncut, removed);
            tmass_remove_tets(whole, cut, ncut, NULL);
        }
        CHECK_INT(TMASS_OK, tmass_hybrid_solve_static(h));
        CHECK_INT(TMASS_OK, tmass_solve_static(whole));
        for (i = 0; i < 3 * mesh.node_count; i++)
            if (fabs((double)tmass_positions(whole)[i] - mesh.nodes[i]) > scale)
                scale = fabs((double)tmass_positions(whole)[i] - mesh.nodes[i]);
        worst = compare_positions(tmass_hybrid_positions(h), &mesh, whole);
        printf("    stage %d: %d connections, max |x_hybrid - x_whole| / max |u| = %.2e (max |u| %.3g m)\n",
               stage, tmass_hybrid_connection_count(h), worst / scale, scale);
        CHECK(worst <= SOLVE_TOL * scale);
    }
    CHECK(tmass_hybrid_connection_count(h) < c0); /* the cut orphaned connection nodes */
    {
        /* contact forces: the precomputed-side contact holds what the whole model's
           constraint force holds */
        tmass_real fh[3], fw[3];
        const tmass_real *f = tmass_forces(whole);
        int r;
        CHECK_INT(TMASS_OK, tmass_hybrid_contact_force(h, qs_node, fh));
        for (r = 0; r < 3; r++)
            fw[r] = -(f[3 * qs_node + r] + tmass_masses(whole)[qs_node] * (r == 2 ? (tmass_real)-9.81 : 0));
        for (r = 0; r < 3; r++) CHECK_NEAR(fw[r], fh[r], 20 * SOLVE_TOL * (fabs(fw[2]) + 1e-3));
        CHECK_INT(TMASS_OK, tmass_hybrid_contact_force(h, dyn_node, fh));
        for (r = 0; r < 3; r++)
            fw[r] = -(f[3 * dyn_node + r] + tmass_masses(whole)[dyn_node] * (r == 2 ? (tmass_real)-9.81 : 0));
        for (r = 0; r < 3; r++) CHECK_NEAR(fw[r], fh[r], 20 * SOLVE_TOL * (fabs(fw[2]) + 1e-3));
    }
    tmass_hybrid_destroy(h);
    tmass_destroy(whole);
    free(rest);
    free(dynamic);
    free(fixed);
    tetmesh_free(&mesh);
}

/* The fig. 5 loop in time: with damping, implicit steps far beyond the explicit limit stay
   stable (the coupling stiffness is implicit) and settle on the whole model's steady
   state; a tool moving on the precomputed part changes its contacts every few steps.
   Implicit Euler, and BDF2 (issue 19: the dynamic part steps like any model). */
static void hybrid_dynamics_settle(tmass_integrator integ)
{
    tetmesh mesh;
    tmass_real *rest;
    unsigned char *dynamic;
    int *fixed, nfixed, s, tool;
    double p_tool[3] = {0.1, 0.05, 0.05}, worst, scale = 0.0;
    tmass_hybrid *h;
    tmass_model *whole;
    int i;
    beam_mesh(&mesh);
    rest = alloc_reals(3 * mesh.node_count);
    dynamic = (unsigned char *)calloc((size_t)mesh.tet_count, 1);
    fixed = (int *)calloc((size_t)mesh.node_count, sizeof(int));
    h = make_hybrid(&mesh, rest, dynamic, fixed, &nfixed);
    REQUIRE(h != NULL);
    tool = tetmesh_nearest_node(&mesh, p_tool);
    tmass_hybrid_dynamic_part(h)->mass_damping = 20; /* settle within a few tenths of a second */
    for (s = 0; s < 200; s++) {
        tmass_real u[3];
        u[0] = 0;
        u[1] = 0;
        u[2] = (tmass_real)(0.004 * (s < 100 ? s / 100.0 : 1.0));
        if (s % 10 == 5 && s < 150) tmass_hybrid_release_node(h, tool); /* lost and regained */
        else tmass_hybrid_set_displacement(h, tool, u);
        CHECK_INT(TMASS_OK, tmass_hybrid_step_ex(h, (tmass_real)0.01, integ));
    }
    whole = beam_model(&mesh, rest);
    {
        tmass_real u[3] = {0, 0, 0.004f};
        tmass_set_displacement(whole, tool, u);
    }
    tmass_solve_static(whole);
    for (i = 0; i < 3 * mesh.node_count; i++)
        if (fabs((double)tmass_positions(whole)[i] - mesh.nodes[i]) > scale)
            scale = fabs((double)tmass_positions(whole)[i] - mesh.nodes[i]);
    worst = compare_positions(tmass_hybrid_positions(h), &mesh, whole);
    printf("    after 2 s of 10 ms %s steps: max |x_hybrid - x_whole_static| / max |u| = %.2e\n",
           integ == TMASS_BDF2 ? "BDF2" : "implicit Euler", worst / scale);
    if (integ == TMASS_BDF2) CHECK_INT(1, tmass_hybrid_dynamic_part(h)->history_ready); /* BDF2 proper */
    CHECK(worst <= 1e-3 * scale);
    tmass_hybrid_destroy(h);
    tmass_destroy(whole);
    free(rest);
    free(dynamic);
    free(fixed);
    tetmesh_free(&mesh);
}

static void test_hybrid_dynamics_settle(void) { hybrid_dynamics_settle(TMASS_IMPLICIT_EULER); }
static void test_hybrid_dynamics_settle_bdf2(void) { hybrid_dynamics_settle(TMASS_BDF2); }

/* Cutting a precomputed tetrahedron is refused with nothing removed; the boundary of the
   whole live mesh stays equal to an independent extraction after cuts at the interface. */
static void test_hybrid_topology(void)
{
    tetmesh mesh;
    tmass_real *rest;
    unsigned char *dynamic;
    int *fixed, nfixed, t, i, qs_tet = -1, dyn_tets[64], nd = 0, *live, kept, *ref, ref_count, count,
        removed;
    const int *tris;
    tmass_hybrid *h;
    tmass_tear_criteria tc = tmass_default_tear_criteria();
    beam_mesh(&mesh);
    rest = alloc_reals(3 * mesh.node_count);
    dynamic = (unsigned char *)calloc((size_t)mesh.tet_count, 1);
    fixed = (int *)calloc((size_t)mesh.node_count, sizeof(int));
    live = (int *)calloc((size_t)4 * mesh.tet_count, sizeof(int));
    h = make_hybrid(&mesh, rest, dynamic, fixed, &nfixed);
    REQUIRE(h != NULL);
    for (t = 0; t < mesh.tet_count; t++) {
        double cx = 0;
        for (i = 0; i < 4; i++) cx += 0.25 * mesh.nodes[3 * mesh.tets[4 * t + i]];
        if (!dynamic[t] && qs_tet < 0) qs_tet = t;
        if (dynamic[t] && cx < 0.2 && nd < 64) dyn_tets[nd++] = t;
    }
    dyn_tets[nd] = qs_tet;
    CHECK_INT(TMASS_ERR_PRECOMPUTED, tmass_hybrid_remove_tets(h, dyn_tets, nd + 1, &removed));
    CHECK_INT(0, removed);
    CHECK_INT(tmass_tet_count(tmass_hybrid_dynamic_part(h)), tmass_live_tet_count(tmass_hybrid_dynamic_part(h)));
    CHECK_INT(TMASS_ERR_TET_RANGE, tmass_hybrid_remove_tets(h, &mesh.tet_count, 1, &removed));
    CHECK_INT(TMASS_OK, tmass_hybrid_remove_tets(h, dyn_tets, nd / 2, &removed));
    CHECK_INT(nd / 2, removed);
    CHECK_INT(TMASS_OK, tmass_hybrid_remove_tets(h, dyn_tets + nd / 2, nd - nd / 2, &removed));
    tc.max_elongation = (tmass_real)10; /* nothing that large: tearing runs, removes none */
    CHECK_INT(TMASS_OK, tmass_hybrid_tear(h, &tc, &removed));
    CHECK_INT(0, removed);
    for (t = 0, kept = 0; t < mesh.tet_count; t++) {
        int alive = !dynamic[t] || tmass_tet_alive(tmass_hybrid_dynamic_part(h), h->tet_local[t]);
        if (alive) memcpy(live + 4 * kept++, mesh.tets + 4 * t, 4 * sizeof(int));
    }
    CHECK_INT(TETMESH_OK, tetmesh_boundary(live, kept, mesh.node_count, &ref, &ref_count));
    tris = tmass_hybrid_boundary_triangles(h, &count);
    CHECK_INT(ref_count, count);
    {
        /* same set of oriented triangles (rotate each so its smallest index leads) */
        int *got = (int *)calloc((size_t)3 * (count + 1), sizeof(int)), k, match = 0;
        memcpy(got, tris, sizeof(int) * 3 * (size_t)count);
        for (i = 0; i < count; i++)
            for (k = 0; k < ref_count; k++) {
                int *a = got + 3 * i, *b = ref + 3 * k, r;
                for (r = 0; r < 3; r++)
                    if (a[0] == b[r] && a[1] == b[(r + 1) % 3] && a[2] == b[(r + 2) % 3]) {
                        match++;
                        break;
                    }
            }
        CHECK_INT(count, match);
        free(got);
    }
    printf("    %d live tets, %d boundary triangles after cutting %d tets at the interface\n", kept,
           count, nd);
    free(ref);
    tmass_hybrid_destroy(h);
    free(rest);
    free(dynamic);
    free(fixed);
    free(live);
    tetmesh_free(&mesh);
}

/* Validation of the hybrid description. */
/* The dynamic part's coarse correction (issue 21) includes the coupling block S: a hybrid
   of a slender beam (1 x 0.1 x 0.1 m, 24 x 2 x 2 cells; the part past x = 0.25 m dynamic,
   over 96 nodes) steps at E = 10 MPa, dt = 0.1 s with the correction always on and never:
   the same positions within the CG tolerance (1e-12; as in test_tensormass.c
   test_implicit_coarse_correction, 1e-4 of the largest displacement, float 1e-2) and
   fewer iterations (measured in double 835 -> 287; with S left out of A_c, a break tried
   on purpose, 458: the check asks for half). */
static void test_hybrid_coarse_correction(void)
{
    tetmesh mesh;
    tmass_real *rest;
    unsigned char *dynamic;
    int *fixed, nfixed = 0, k, s, i, t, cg[2] = {0, 0}, n3;
    tmass_hybrid *h[2];
    double umax = 0, dmax = 0;
    tmass_real g[3] = {0, 0, (tmass_real)-1};
    tetmesh_beam(&mesh, 1.0, 0.1, 0.1, 24, 2, 2, TETMESH_SPLIT5);
    n3 = 3 * mesh.node_count;
    rest = alloc_reals(n3);
    dynamic = (unsigned char *)calloc((size_t)mesh.tet_count, 1);
    fixed = (int *)calloc((size_t)mesh.node_count, sizeof(int));
    for (t = 0; t < mesh.tet_count; t++) {
        double cx = 0;
        for (i = 0; i < 4; i++) cx += 0.25 * mesh.nodes[3 * mesh.tets[4 * t + i]];
        dynamic[t] = cx > 0.25;
    }
    for (i = 0; i < mesh.node_count; i++)
        if (mesh.nodes[3 * i] == 0.0) fixed[nfixed++] = i;
    for (k = 0; k < 2; k++) {
        tmass_hybrid_desc hd = tmass_hybrid_default_desc();
        hd.model = beam_desc(&mesh, rest);
        hd.model.young_modulus = (tmass_real)1e7;
        hd.model.implicit_coarse = k ? 1 : -1;
        for (i = 0; i < 3; i++) hd.model.gravity[i] = g[i];
        hd.tet_dynamic = dynamic;
        hd.fixed_nodes = fixed;
        hd.fixed_count = nfixed;
        h[k] = NULL;
        CHECK_INT(TMASS_OK, tmass_hybrid_create(&hd, &h[k]));
        REQUIRE(h[k] != NULL);
        CHECK(tmass_hybrid_dynamic_part(h[k])->coupling_count > 0);
        CHECK(k == 0 || tmass_hybrid_dynamic_part(h[k])->agg_count > 0);
    }
    for (s = 0; s < 5; s++) {
        for (k = 0; k < 2; k++) {
            CHECK_INT(TMASS_OK, tmass_hybrid_step_ex(h[k], (tmass_real)0.1, TMASS_IMPLICIT_EULER));
            cg[k] += tmass_last_stats(tmass_hybrid_dynamic_part(h[k]))->cg_iterations;
            CHECK_INT(k, tmass_last_stats(tmass_hybrid_dynamic_part(h[k]))->coarse_solves);
        }
        for (i = 0; i < n3; i++) {
            double u = fabs((double)tmass_hybrid_positions(h[0])[i] - mesh.nodes[i]);
            double d = fabs((double)tmass_hybrid_positions(h[1])[i] - (double)tmass_hybrid_positions(h[0])[i]);
            umax = u > umax ? u : umax;
            dmax = d > dmax ? d : dmax;
        }
    }
    printf("    hybrid, 5 steps of 0.1 s: CG iterations Jacobi %d, with the coarse correction %d; largest u %.4g m, "
           "difference %.3g m\n", cg[0], cg[1], umax, dmax);
    CHECK(umax > 1e-5);
    CHECK(dmax <= (IS_FLOAT ? 1e-2 : 1e-4) * umax);
    CHECK(2 * cg[1] < cg[0]);
    for (k = 0; k < 2; k++) tmass_hybrid_destroy(h[k]);
    free(rest);
    free(dynamic);
    free(fixed);
    tetmesh_free(&mesh);
}

static void test_hybrid_validation(void)
{
    tetmesh mesh;
    tmass_real *rest;
    unsigned char *dynamic;
    tmass_hybrid_desc hd = tmass_hybrid_default_desc(), bad;
    tmass_hybrid *h;
    int t, bad_fixed = -1;
    beam_mesh(&mesh);
    rest = alloc_reals(3 * mesh.node_count);
    dynamic = (unsigned char *)calloc((size_t)mesh.tet_count, 1);
    hd.model = beam_desc(&mesh, rest);
    hd.tet_dynamic = dynamic;
    bad = hd; bad.internal_cookie = 1;
    CHECK_INT(TMASS_ERR_DESC, tmass_hybrid_create(&bad, &h));
    CHECK_INT(TMASS_ERR_ARG, tmass_hybrid_create(&hd, &h)); /* no dynamic tet */
    for (t = 0; t < mesh.tet_count; t++) dynamic[t] = 1;
    CHECK_INT(TMASS_ERR_ARG, tmass_hybrid_create(&hd, &h)); /* no precomputed tet */
    dynamic[0] = 0;
    bad = hd; bad.tet_dynamic = NULL;
    CHECK_INT(TMASS_ERR_ARG, tmass_hybrid_create(&bad, &h));
    bad = hd; bad.fixed_nodes = &bad_fixed; bad.fixed_count = 1;
    CHECK_INT(TMASS_ERR_NODE_RANGE, tmass_hybrid_create(&bad, &h));
    bad = hd; bad.model.kind = TMASS_MASS_SPRING;
    CHECK_INT(TMASS_ERR_MODEL_KIND, tmass_hybrid_create(&bad, &h));
    bad = hd; bad.model.young_modulus = -1;
    CHECK_INT(TMASS_ERR_YOUNG_MODULUS, tmass_hybrid_create(&bad, &h));
    /* no fixed node: no piece of the precomputed part is held, so all of it would move to
       the dynamic part, leaving nothing precomputed */
    CHECK_INT(TMASS_ERR_ARG, tmass_hybrid_create(&hd, &h));
    free(rest);
    free(dynamic);
    tetmesh_free(&mesh);
}


/* ---- issue 18 ---------------------------------------------------------------------- */

/* Issue 18 item 7: pinned nodes that are not at rest (driven by tmass_set_displacement)
   are boundary conditions of the precomputation: the preload with no contact equals the
   direct static solve with those targets, at every node. */
static void test_qs_pinned_not_at_rest(void)
{
    tetmesh mesh;
    tmass_real *rest, drive[3] = {0.004f, -0.002f, 0.01f};
    tmass_model *m, *direct;
    tmass_qs *qs = NULL;
    tmass_qs_desc qd = tmass_qs_default_desc();
    int i, r, driven = 0;
    double worst = 0.0;
    beam_mesh(&mesh);
    rest = alloc_reals(3 * mesh.node_count);
    m = beam_model(&mesh, rest);
    direct = beam_model(&mesh, rest);
    REQUIRE(m != NULL && direct != NULL);
    for (i = 0; i < mesh.node_count; i++) /* the clamped face is driven */
        if (mesh.nodes[3 * i] == 0.0) {
            tmass_set_displacement(m, i, drive);
            tmass_set_displacement(direct, i, drive);
            driven++;
        }
    REQUIRE(driven > 0);
    qd.all_nodes = 1;
    CHECK_INT(TMASS_OK, tmass_qs_create(m, &qd, &qs));
    REQUIRE(qs != NULL);
    CHECK_INT(TMASS_OK, tmass_qs_update(qs, NULL, NULL, 0, NULL));
    CHECK_INT(TMASS_OK, tmass_solve_static(direct));
    for (i = 0; i < mesh.node_count; i++)
        for (r = 0; r < 3; r++) {
            double d = fabs((double)tmass_qs_displacements(qs)[3 * i + r] -
                            ((double)tmass_positions(direct)[3 * i + r] - (double)rest[3 * i + r]));
            if (d > worst) worst = d;
        }
    printf("    driven clamp: max |u_qs - u_static| / |u_drive| = %.2e\n", worst / 0.01);
    CHECK(worst <= SOLVE_TOL * 0.01 + (IS_FLOAT ? 1e-6 : 0));
    tmass_qs_destroy(qs);
    tmass_destroy(direct);
    tmass_destroy(m);
    free(rest);
    tetmesh_free(&mesh);
}

static unsigned long long fnv1a(const unsigned char *p, size_t n)
{
    unsigned long long h = 14695981039346656037ull;
    size_t i;
    for (i = 0; i < n; i++) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

/* Issue 18 item 15: a file with a NaN (or an infinity) in its payload and a recomputed,
   valid checksum is refused, in the preload and in the compliance. */
static void test_qs_load_refuses_non_finite(void)
{
    tetmesh mesh;
    tmass_real *rest, bad[2];
    tmass_model *m;
    tmass_qs *qs, *back;
    tmass_qs_desc qd = tmass_qs_default_desc();
    unsigned char *buf;
    size_t size = 0, payload, where[2];
    unsigned long long sum;
    int k, w;
    beam_mesh(&mesh);
    rest = alloc_reals(3 * mesh.node_count);
    m = beam_model(&mesh, rest);
    REQUIRE(m != NULL);
    REQUIRE(tmass_qs_create(m, &qd, &qs) == TMASS_OK);
    tmass_qs_save_memory(qs, NULL, 0, &size);
    buf = (unsigned char *)malloc(size);
    REQUIRE(tmass_qs_save_memory(qs, buf, size, &size) == TMASS_OK);
    payload = size - TMASS__QS_HEADER_BYTES - 8;
    bad[0] = (tmass_real)NAN;
    bad[1] = (tmass_real)INFINITY;
    where[0] = TMASS__QS_HEADER_BYTES + sizeof(tmass_real) * 7;                         /* preload */
    where[1] = TMASS__QS_HEADER_BYTES + sizeof(tmass_real) * (3 * (size_t)mesh.node_count + 5); /* compliance */
    for (k = 0; k < 2; k++)
        for (w = 0; w < 2; w++) {
            unsigned char *copy = (unsigned char *)malloc(size);
            memcpy(copy, buf, size);
            memcpy(copy + where[w], &bad[k], sizeof(tmass_real));
            sum = fnv1a(copy + TMASS__QS_HEADER_BYTES, payload);
            memcpy(copy + TMASS__QS_HEADER_BYTES + payload, &sum, 8);
            back = NULL;
            CHECK_INT(TMASS_ERR_FILE_FORMAT, tmass_qs_load_memory(m, &qd, copy, size, &back));
            CHECK(back == NULL);
            if (back) tmass_qs_destroy(back);
            free(copy);
        }
    free(buf);
    tmass_qs_destroy(qs);
    tmass_destroy(m);
    free(rest);
    tetmesh_free(&mesh);
}

static void count_log(int code, const char *message, void *user)
{
    (void)code;
    (void)message;
    ++*(int *)user;
}

/* Issue 18 item 12: descriptions not made by their default function (filled with 0xA5
   bytes, so their log callback is a wild pointer) are refused with TMASS_ERR_DESC, never
   called into. */
static void test_garbage_descs_refused(void)
{
    tetmesh mesh;
    tmass_real *rest;
    tmass_model *m;
    tmass_qs *qs = (tmass_qs *)&mesh;
    tmass_hybrid *h = (tmass_hybrid *)&mesh;
    tmass_qs_desc qd;
    tmass_hybrid_desc hd;
    unsigned char dynamic[1] = {1};
    int calls = 0;
    beam_mesh(&mesh);
    rest = alloc_reals(3 * mesh.node_count);
    m = beam_model(&mesh, rest);
    REQUIRE(m != NULL);
    memset(&qd, 0xA5, sizeof qd);
    CHECK_INT(TMASS_ERR_DESC, tmass_qs_create(m, &qd, &qs));
    CHECK(qs == NULL);
    memset(&hd, 0xA5, sizeof hd);
    CHECK_INT(TMASS_ERR_DESC, tmass_hybrid_create(&hd, &h));
    CHECK(h == NULL);
    /* a genuine hybrid desc around a garbage model desc */
    hd = tmass_hybrid_default_desc();
    memset(&hd.model, 0xA5, sizeof hd.model);
    hd.tet_dynamic = dynamic;
    h = (tmass_hybrid *)&mesh;
    CHECK_INT(TMASS_ERR_DESC, tmass_hybrid_create(&hd, &h));
    CHECK(h == NULL);
    /* a garbage desc with a valid log: refused, and no callback is trusted */
    memset(&hd.model, 0xA5, sizeof hd.model);
    hd.model.log = count_log;
    hd.model.log_user = &calls;
    CHECK_INT(TMASS_ERR_DESC, tmass_hybrid_create(&hd, &h));
    tmass_destroy(m);
    free(rest);
    tetmesh_free(&mesh);
}

static const test_case cases[] = {
    TEST(test_qs_matches_direct_solve),
    TEST(test_qs_compliance_symmetric),
    TEST(test_qs_progress_and_cancel),
    TEST(test_qs_save_load),
    TEST(test_qs_validation),
    TEST(test_hybrid_equals_whole),
    TEST(test_hybrid_dynamics_settle),
    TEST(test_hybrid_dynamics_settle_bdf2),
    TEST(test_hybrid_topology),
    TEST(test_hybrid_coarse_correction),
    TEST(test_hybrid_validation),
    TEST(test_qs_pinned_not_at_rest),
    TEST(test_qs_load_refuses_non_finite),
    TEST(test_garbage_descs_refused),
};

int main(int argc, char **argv) { return TEST_MAIN(argc, argv, cases); }
