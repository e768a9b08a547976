/* tensormass_cut.c - cutting with tensormass.h (Cotin et al. sec. 5.5, fig. 2).

   A soft plate held at its four corners sags under gravity while a scalpel moving along
   the middle line removes the tetrahedra it touches; the plate opens and sags further.
   Writes VTK frames (live tetrahedra, displacement field) to the directory given as the
   first argument (default: the current directory) and prints one line per simulated
   second. Runs in about 9 s (gcc -O2, one core of this project's machine).
   Build: cc examples/tensormass_cut.c -lm       Run: ./a.out [output-directory]
   Exit status 0, 1 when a step fails or a file or the printout cannot be written, 2 for
   a bad argument. */
#define TENSORMASS_IMPLEMENTATION
#include "../tensormass.h"
#define TETMESH_IMPLEMENTATION
#include "tetmesh.h"
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define SIDE 0.2       /* m, plate side */
#define THICK 0.01     /* m */
#define DURATION 4.0   /* s of simulated time */
#define DT 2e-3        /* s */
#define CUT_START 1.0  /* s: the scalpel enters ... */
#define CUT_SPEED 0.06 /* m/s: ... and moves along y = SIDE / 2 */

static void usage(void)
{
    fprintf(stderr, "usage: tensormass_cut [output-directory]\n");
    exit(2);
}

/* 1 if a file can be created in dir: checked first, so a bad directory fails at once. */
static int writable(const char *dir)
{
    char path[512];
    FILE *f;
    snprintf(path, sizeof path, "%s/.tensormass_cut_probe", dir);
    f = fopen(path, "w");
    if (!f) return 0;
    if (fclose(f) != 0) return 0;
    remove(path);
    return 1;
}

/* Writes the live tetrahedra and the displacement field; 0 or a tetmesh error (printed). */
static int write_frame(const char *dir, int frame, const tmass_model *m, const tetmesh *mesh,
                       int *live)
{
    char path[512];
    int t, count = 0, i, n = tmass_node_count(m), err;
    tmass_real *u = (tmass_real *)malloc(sizeof(tmass_real) * 3 * (size_t)n);
    tetmesh_field field;
    for (t = 0; t < mesh->tet_count; t++)
        if (tmass_tet_alive(m, t) == 1) memcpy(live + 4 * count++, mesh->tets + 4 * t, 4 * sizeof(int));
    for (i = 0; i < 3 * n; i++) u[i] = tmass_positions(m)[i] - tmass_rest_positions(m)[i];
    field.name = "displacement";
    field.components = 3;
    field.type = TETMESH_TYPE_OF(u[0]);
    field.data = u;
    snprintf(path, sizeof path, "%s/tensormass_cut_%03d.vtk", dir, frame);
    err = tetmesh_write_vtk(path, tmass_positions(m), TETMESH_TYPE_OF(u[0]), n, live, count, &field, 1);
    if (err) fprintf(stderr, "tensormass_cut: cannot write %s: %s\n", path, tetmesh_error_string(err));
    free(u);
    return err;
}

int main(int argc, char **argv)
{
    const char *dir = ".";
    double lo[3] = {0, 0, 0}, hi[3] = {SIDE, SIDE, THICK}, centre[3] = {SIDE / 2, SIDE / 2, 0};
    tetmesh mesh;
    tmass_desc d = tmass_default_desc();
    tmass_model *m;
    tmass_real *rest;
    int *live, *cut, i, t, step, steps = (int)(DURATION / DT + 0.5), frame = 0, mid, err;
    double cpu = 0.0;

    if (argc > 2 || (argc == 2 && argv[1][0] == '-')) usage();
    if (argc == 2) dir = argv[1];
    if (!writable(dir)) {
        fprintf(stderr, "tensormass_cut: cannot write in directory '%s'\n", dir);
        return 1;
    }
    /* 16 x 16 x 2 cells of 5 tetrahedra: 2560 tets, 867 nodes (the paper's plate: 2212, 759) */
    tetmesh_box(&mesh, lo, hi, 16, 16, 2, TETMESH_SPLIT5);
    rest = (tmass_real *)malloc(sizeof(tmass_real) * 3 * (size_t)mesh.node_count);
    for (i = 0; i < 3 * mesh.node_count; i++) rest[i] = (tmass_real)mesh.nodes[i];
    d.rest_positions = rest;
    d.node_count = mesh.node_count;
    d.tets = mesh.tets;
    d.tet_count = mesh.tet_count;
    d.young_modulus = 3e5;     /* Pa: a firm soft tissue */
    d.poisson_ratio = 0.35;
    d.density = 1000;
    d.mass_damping = 2.0;      /* 1/s: settles in about a second */
    d.time_step = DT;
    d.integrator = TMASS_IMPLICIT_EULER;
    err = tmass_create(&d, &m);
    if (err) {
        fprintf(stderr, "tmass_create: %s\n", tmass_error_string(err));
        return 1;
    }
    /* hold the four vertical corner edges */
    for (i = 0; i < mesh.node_count; i++) {
        const double *p = mesh.nodes + 3 * i;
        if ((p[0] == 0 || p[0] == SIDE) && (p[1] == 0 || p[1] == SIDE)) tmass_fix_node(m, i);
    }
    mid = tetmesh_nearest_node(&mesh, centre);
    live = (int *)malloc(sizeof(int) * 4 * (size_t)mesh.tet_count);
    cut = (int *)malloc(sizeof(int) * (size_t)mesh.tet_count);

    printf("t [s]  centre sag [mm]  live tets  boundary tris  cut [mm]  ms/step  CG iterations\n");
    for (step = 1; step <= steps; step++) {
        double now = step * DT, blade = (now - CUT_START) * CUT_SPEED;
        int count = 0, tris;
        clock_t c0;
        /* the scalpel removes every tetrahedron whose centroid is near its path so far */
        if (blade > 0) {
            for (t = 0; t < mesh.tet_count; t++) {
                double cx = 0, cy = 0;
                int j;
                if (tmass_tet_alive(m, t) != 1) continue;
                for (j = 0; j < 4; j++) {
                    cx += 0.25 * mesh.nodes[3 * mesh.tets[4 * t + j]];
                    cy += 0.25 * mesh.nodes[3 * mesh.tets[4 * t + j] + 1];
                }
                if (cx < blade && cx < 0.8 * SIDE && fabs(cy - SIDE / 2) < 0.4 * SIDE / 16) cut[count++] = t;
            }
        }
        c0 = clock();
        err = count ? tmass_remove_tets(m, cut, count, NULL) : 0;
        if (!err) err = tmass_step(m);
        cpu += (double)(clock() - c0) / CLOCKS_PER_SEC;
        if (err) {
            fprintf(stderr, "step %d: %s\n", step, tmass_error_string(err));
            break;
        }
        if (step % (int)(0.2 / DT + 0.5) == 0) {
            if (write_frame(dir, frame, m, &mesh, live)) {
                err = 1;
                break;
            }
            frame++;
        }
        if (step % (int)(1.0 / DT + 0.5) == 0) {
            tmass_boundary_triangles(m, &tris);
            printf("%5.1f  %15.3f  %9d  %13d  %8.1f  %7.3f  %13d\n", now,
                   -1000.0 * (tmass_positions(m)[3 * mid + 2] - mesh.nodes[3 * mid + 2]),
                   tmass_live_tet_count(m), tris, blade > 0 ? 1000 * (blade < 0.8 * SIDE ? blade : 0.8 * SIDE) : 0.0,
                   1000.0 * cpu / step, tmass_last_stats(m)->cg_iterations);
        }
    }
    if (!err) printf("%d VTK frames written to %s/tensormass_cut_*.vtk\n", frame, dir);
    free(live);
    free(cut);
    free(rest);
    tmass_destroy(m);
    tetmesh_free(&mesh);
    if (fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, "tensormass_cut: writing to standard output failed\n");
        return 1;
    }
    return err ? 1 : 0;
}
