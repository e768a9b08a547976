/* frames_beam.c - the thesis's steel cantilever with 6-DoF frames (frames.h; REFERENCES R1,
   Bosman 2015 sec. 4.3): 16 x 0.5 x 0.5 m, E = 200 GPa, 31200 kg, clamped at x = 0 and
   bending under its own weight, with 25 x 5 x 5 frames on a hexahedral grid (trilinear
   shape functions) and 8 samples per cell. Prints the tip deflection after each Newton
   iteration against the converged 3D solid's 0.150169 m (REFERENCES R1), writes the samples and the frames as legacy
   VTK point clouds and the deformed body as a tetrahedral render mesh (finer than the
   frames) whose vertices are mapped points (frm_probe_*: this is how a frames body is
   drawn), then times the mapped points in nanoseconds per vertex and the conjugate
   gradient's product K v in nanoseconds per (sample, neighbour) pair. Runs in about 1 s (gcc -O2, one core of this project's
   machine).

       cc examples/frames_beam.c -lm && ./a.out [output-directory]

   The VTK files go to the directory given (default: the current one). Exit status 0, 1
   when the model fails or a file or the printout cannot be written, 2 for a bad argument. */
#define FRAMES_IMPLEMENTATION
#include "../frames.h"
#define TETMESH_IMPLEMENTATION
#include "tetmesh.h"
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static void usage(void)
{
    fprintf(stderr, "usage: frames_beam [output-directory]\n");
    exit(2);
}

/* 1 if a file can be created in dir: checked first, so a bad directory fails at once
   instead of after the solve. */
static int writable(const char *dir)
{
    char path[512];
    FILE *f;
    snprintf(path, sizeof path, "%s/.frames_beam_probe", dir);
    f = fopen(path, "w");
    if (!f) return 0;
    if (fclose(f) != 0) return 0;
    remove(path);
    return 1;
}

/* Nanoseconds per pair of one K v product in the given mode (best of 5 runs of 20). */
static double time_product(frm_model *m, frm_stiffness_mode mode, const frm_real *v, frm_real *out)
{
    double best = 1e30;
    int run, k;
    frm_model_set_stiffness_mode(m, mode);
    frm_model_prepare_stiffness(m);
    for (run = 0; run < 5; run++) {
        clock_t t0 = clock();
        for (k = 0; k < 20; k++) frm_model_apply_stiffness(m, v, out, 1);
        if ((double)(clock() - t0) < best) best = (double)(clock() - t0);
    }
    return best / CLOCKS_PER_SEC / 20 * 1e9 / frm_model_pair_count(m);
}

int main(int argc, char **argv)
{
    const char *dir = ".";
    char samples_path[512], frames_path[512], render_path[512];
    const double L = 16, W = 0.5, lo[3] = {0, -W / 2, -W / 2}, hi[3] = {L, W / 2, W / 2};
    hexmesh grid;
    frm_sampling s;
    frm_desc d = frm_model_default_desc();
    frm_model *m;
    frm_real *nodes, *v, *out, residual, load = 0;
    int i, n, tip = -1, err;

    if (argc > 2 || (argc == 2 && argv[1][0] == '-')) usage();
    if (argc == 2) dir = argv[1];
    if (!writable(dir)) {
        fprintf(stderr, "frames_beam: cannot write in directory '%s'\n", dir);
        return 1;
    }
    snprintf(samples_path, sizeof samples_path, "%s/frames_beam_samples.vtk", dir);
    snprintf(frames_path, sizeof frames_path, "%s/frames_beam_frames.vtk", dir);
    snprintf(render_path, sizeof render_path, "%s/frames_beam_render.vtk", dir);

    /* frames at the grid's nodes, 2 x 2 x 2 samples per cell at the sub-cell centres */
    hexmesh_grid(&grid, lo, hi, 24, 4, 4);
    nodes = (frm_real *)malloc(sizeof(frm_real) * 3 * grid.node_count);
    for (i = 0; i < 3 * grid.node_count; i++) nodes[i] = (frm_real)grid.nodes[i];
    err = frm_sampling_hexes(&s, nodes, grid.node_count, grid.hexes, grid.hex_count, 2, FRM_QUADRATURE_SUBCELL, NULL);
    if (err) {
        fprintf(stderr, "sampling: %s\n", frm_error_string(err));
        return 1;
    }
    frm_sampling_apply(&s, &d);
    d.material.young_modulus = (frm_real)200e9; /* Pa */
    d.material.poisson_ratio = (frm_real)0.3;
    d.material.density = (frm_real)(31200 / (L * W * W)); /* kg/m^3 */
    d.cg_tolerance = (frm_real)1e-10;                     /* the thesis's CG precision */
    d.cg_max_iterations = 20000;
    err = frm_model_create(&d, &m);
    if (err) {
        fprintf(stderr, "create: %s\n", frm_error_string(err));
        return 1;
    }
    n = frm_model_frame_count(m);
    for (i = 0; i < n; i++) {
        const double *x = grid.nodes + 3 * i;
        if (x[0] == 0) frm_model_fix_frame(m, i); /* the clamp: position and orientation */
        if (x[0] == L && x[1] == 0 && x[2] == 0) tip = i;
    }
    printf("%d frames, %d samples, %d (sample, frame) pairs\n", n, frm_model_sample_count(m), frm_model_pair_count(m));

    /* static equilibrium, one Newton iteration at a time */
    for (i = 1; i <= 10; i++) {
        const frm_stats *st;
        err = frm_model_newton_step(m, &residual);
        st = frm_model_last_stats(m);
        if (err) {
            fprintf(stderr, "Newton: %s\n", frm_error_string(err));
            return 1;
        }
        if (i == 1) load = st->initial_residual; /* |f| at rest: the weight */
        printf("Newton %d: tip deflection %.6f m (3D solid 0.150169), residual %.3g, %d CG iterations\n", i,
               -(double)frm_model_positions(m)[3 * tip + 2], (double)residual, st->cg_iterations);
        if (residual < 1e-6 * load) break;
    }

    { /* samples (volumetric strain J - 1) and frames (their x axes) for a viewer */
        const frm_real *F = frm_model_deformation_gradients(m), *q = frm_model_orientations(m);
        int S = frm_model_sample_count(m);
        frm_real *strain = (frm_real *)malloc(sizeof(frm_real) * S), *axis = (frm_real *)malloc(sizeof(frm_real) * 3 * n);
        tetmesh_field fs, ff;
        for (i = 0; i < S; i++) {
            const frm_real *A = F + 9 * i;
            strain[i] = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
                        A[2] * (A[3] * A[7] - A[4] * A[6]) - 1;
        }
        for (i = 0; i < n; i++) { /* first column of the rotation matrix */
            const frm_real *p = q + 4 * i;
            axis[3 * i] = 1 - 2 * (p[1] * p[1] + p[2] * p[2]);
            axis[3 * i + 1] = 2 * (p[0] * p[1] + p[2] * p[3]);
            axis[3 * i + 2] = 2 * (p[0] * p[2] - p[1] * p[3]);
        }
        fs.name = "volume_change";
        fs.components = 1;
        fs.type = TETMESH_TYPE_OF(frm_real);
        fs.data = strain;
        ff.name = "x_axis";
        ff.components = 3;
        ff.type = TETMESH_TYPE_OF(frm_real);
        ff.data = axis;
        err = tetmesh_write_vtk(samples_path, frm_model_sample_positions(m), TETMESH_TYPE_OF(frm_real), S, NULL, 0,
                                &fs, 1);
        if (err) fprintf(stderr, "frames_beam: cannot write %s: %s\n", samples_path, tetmesh_error_string(err));
        else {
            err = tetmesh_write_vtk(frames_path, frm_model_positions(m), TETMESH_TYPE_OF(frm_real), n, NULL, 0, &ff, 1);
            if (err) fprintf(stderr, "frames_beam: cannot write %s: %s\n", frames_path, tetmesh_error_string(err));
        }
        free(strain);
        free(axis);
        if (err) return 1;
        printf("wrote %s and %s\n", samples_path, frames_path);
    }

    { /* a render mesh (48 x 4 x 4 cells, 5 tetrahedra each) skinned by the frames: its vertices
         are mapped points, found once in the frames' hexahedra (their trilinear weights), then
         placed by eq. 3.34 at every frame; here once, and timed */
        tetmesh render;
        frm_probe_desc pd = frm_probe_default_desc();
        frm_probe *probe = NULL;
        frm_real *rest, *deformed;
        clock_t t0;
        int k, calls = 200;
        if (tetmesh_box(&render, lo, hi, 48, 4, 4, TETMESH_SPLIT5) != TETMESH_OK) return 1;
        rest = (frm_real *)malloc(sizeof(frm_real) * 3 * render.node_count);
        deformed = (frm_real *)malloc(sizeof(frm_real) * 3 * render.node_count);
        for (i = 0; i < 3 * render.node_count; i++) rest[i] = (frm_real)render.nodes[i];
        pd.kind = FRM_PROBE_HEXES; /* the frames' own shape functions: frame i is grid node i */
        pd.elements = grid.hexes;
        pd.element_count = grid.hex_count;
        err = frm_probe_create(m, &pd, rest, render.node_count, &probe);
        if (err) {
            fprintf(stderr, "render mesh: %s\n", frm_error_string(err));
            return 1;
        }
        t0 = clock();
        for (k = 0; k < calls; k++) frm_probe_positions(probe, m, deformed);
        printf("render mesh: %d vertices placed by the frames in %.1f ns a vertex\n", render.node_count,
               (double)(clock() - t0) / CLOCKS_PER_SEC / calls * 1e9 / render.node_count);
        err = tetmesh_write_vtk(render_path, deformed, TETMESH_TYPE_OF(frm_real), render.node_count, render.tets,
                                render.tet_count, NULL, 0);
        if (err) fprintf(stderr, "frames_beam: cannot write %s: %s\n", render_path, tetmesh_error_string(err));
        else printf("wrote %s\n", render_path);
        frm_probe_destroy(probe);
        free(rest);
        free(deformed);
        tetmesh_free(&render);
        if (err) return 1;
    }

    /* the CG's product at this linearisation: matrix-free over the pairs, or by blocks */
    v = (frm_real *)malloc(sizeof(frm_real) * 6 * n);
    out = (frm_real *)malloc(sizeof(frm_real) * 6 * n);
    for (i = 0; i < 6 * n; i++) v[i] = (frm_real)(1e-3 * ((i * 7) % 11 - 5));
    printf("K v matrix-free: %.1f ns per pair (design target 20 ns, double, one core)\n",
           time_product(m, FRM_STIFFNESS_PAIRS, v, out));
    printf("K v by 6x6 blocks: %.1f ns per pair\n", time_product(m, FRM_STIFFNESS_BLOCKS, v, out));

    free(v);
    free(out);
    free(nodes);
    frm_model_destroy(m);
    frm_sampling_free(&s);
    hexmesh_free(&grid);
    if (fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, "frames_beam: writing to standard output failed\n");
        return 1;
    }
    return 0;
}
