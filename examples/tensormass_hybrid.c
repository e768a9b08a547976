/* tensormass_hybrid.c - the hybrid model of tensormass.h (Cotin et al. sec. 6, fig. 7-8).

   A liver-like blob (an ellipsoid) hangs from its top. Its lower right lobe is a dynamic
   tensor-mass part that a scalpel cuts along a line; the rest is precomputed and a tool
   pushes its underside. Prints the precomputation cost, then per-update times and the
   force the tool feels, and writes VTK frames of the live mesh to the directory given
   (default: the current directory).
   Build: cc examples/tensormass_hybrid.c -lm      Run: ./a.out [--full] [output-directory]
   By default the ellipsoid has 12 cells across (about 1.5 s, most of it the
   precomputation); --full uses 20 (5,800 tetrahedra, about 40 s, of which 30 s
   precomputing 1,594 solves; gcc -O2, one core of this project's machine). Exit status
   0, 1 when a step fails or a file or the printout cannot be written, 2 for a bad
   argument. */
#define TENSORMASS_IMPLEMENTATION
#include "../tensormass.h"
#define TETMESH_IMPLEMENTATION
#include "tetmesh.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define DT 0.01       /* s: a 100 Hz simulation loop */
#define DURATION 2.0  /* s */

static void usage(void)
{
    fprintf(stderr, "usage: tensormass_hybrid [--full] [output-directory]\n");
    exit(2);
}

/* 1 if a file can be created in dir: checked first, so a bad directory fails at once. */
static int writable(const char *dir)
{
    char path[512];
    FILE *f;
    snprintf(path, sizeof path, "%s/.tensormass_hybrid_probe", dir);
    f = fopen(path, "w");
    if (!f) return 0;
    if (fclose(f) != 0) return 0;
    remove(path);
    return 1;
}

static int show_progress(int done, int total, void *user)
{
    (void)user;
    if (done == total || done % 500 == 0) fprintf(stderr, "\rprecomputing %d / %d", done, total);
    if (done == total) fprintf(stderr, "\n");
    return 0; /* non-zero would cancel */
}

static double centroid(const tetmesh *mesh, int t, int axis)
{
    double c = 0.0;
    int j;
    for (j = 0; j < 4; j++) c += 0.25 * mesh->nodes[3 * mesh->tets[4 * t + j] + axis];
    return c;
}

/* Writes the live tetrahedra and the displacement field; 0 or a tetmesh error (printed). */
static int write_frame(const char *dir, int frame, tmass_hybrid *h, const tetmesh *mesh,
                       const unsigned char *dynamic, int *live)
{
    char path[512];
    int t, count = 0, i, dyn_t = 0, err;
    tmass_model *dyn = tmass_hybrid_dynamic_part(h);
    tmass_real *u = (tmass_real *)malloc(sizeof(tmass_real) * 3 * (size_t)mesh->node_count);
    tetmesh_field field;
    for (t = 0; t < mesh->tet_count; t++) {
        int alive = !dynamic[t] || tmass_tet_alive(dyn, dyn_t) == 1;
        dyn_t += dynamic[t];
        if (alive) memcpy(live + 4 * count++, mesh->tets + 4 * t, 4 * sizeof(int));
    }
    for (i = 0; i < 3 * mesh->node_count; i++) u[i] = (tmass_real)(tmass_hybrid_positions(h)[i] - mesh->nodes[i]);
    field.name = "displacement";
    field.components = 3;
    field.type = TETMESH_TYPE_OF(u[0]);
    field.data = u;
    snprintf(path, sizeof path, "%s/tensormass_hybrid_%03d.vtk", dir, frame);
    err = tetmesh_write_vtk(path, tmass_hybrid_positions(h), TETMESH_TYPE_OF(u[0]), mesh->node_count, live, count,
                            &field, 1);
    if (err) fprintf(stderr, "tensormass_hybrid: cannot write %s: %s\n", path, tetmesh_error_string(err));
    free(u);
    return err;
}

int main(int argc, char **argv)
{
    const char *dir = ".";
    const double radii[3] = {0.14, 0.09, 0.06}, tool_at[3] = {-0.07, 0.0, -0.06};
    tetmesh mesh;
    tmass_hybrid_desc d = tmass_hybrid_default_desc();
    tmass_hybrid *h;
    tmass_real *rest;
    unsigned char *dynamic;
    int *fixed, *live, *cut, nfixed = 0, i, t, step, steps = (int)(DURATION / DT + 0.5), err, tool, frame = 0;
    double seconds = 0.0, t0;
    int cells = 12, have_dir = 0;

    for (i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--full") == 0) cells = 20;
        else if (argv[i][0] == '-' || have_dir) usage();
        else dir = argv[i], have_dir = 1;
    }
    if (!writable(dir)) {
        fprintf(stderr, "tensormass_hybrid: cannot write in directory '%s'\n", dir);
        return 1;
    }
    err = tetmesh_ellipsoid(&mesh, radii, cells);
    if (err) {
        fprintf(stderr, "tetmesh_ellipsoid: %s\n", tetmesh_error_string(err));
        return 1;
    }
    rest = (tmass_real *)malloc(sizeof(tmass_real) * 3 * (size_t)mesh.node_count);
    dynamic = (unsigned char *)malloc((size_t)mesh.tet_count);
    fixed = (int *)malloc(sizeof(int) * (size_t)mesh.node_count);
    live = (int *)malloc(sizeof(int) * 4 * (size_t)mesh.tet_count);
    cut = (int *)malloc(sizeof(int) * (size_t)mesh.tet_count);
    for (i = 0; i < 3 * mesh.node_count; i++) rest[i] = (tmass_real)mesh.nodes[i];
    for (i = 0; i < mesh.node_count; i++) /* the top cap is attached */
        if (mesh.nodes[3 * i + 2] > 0.7 * radii[2]) fixed[nfixed++] = i;
    for (t = 0; t < mesh.tet_count; t++) /* the lower right lobe is where surgery happens */
        dynamic[t] = centroid(&mesh, t, 0) > 0.03 && centroid(&mesh, t, 2) < 0.0;
    tool = tetmesh_nearest_node(&mesh, tool_at);

    d.model.rest_positions = rest;
    d.model.node_count = mesh.node_count;
    d.model.tets = mesh.tets;
    d.model.tet_count = mesh.tet_count;
    d.model.young_modulus = 3e4; /* Pa */
    d.model.poisson_ratio = 0.4;
    d.model.density = 1000;
    d.model.mass_damping = 5;    /* 1/s */
    d.model.time_step = DT;
    d.model.integrator = TMASS_IMPLICIT_EULER;
    d.tet_dynamic = dynamic;
    d.fixed_nodes = fixed;
    d.fixed_count = nfixed;
    d.precompute.progress = show_progress;
    t0 = (double)clock() / CLOCKS_PER_SEC;
    err = tmass_hybrid_create(&d, &h);
    if (err) {
        fprintf(stderr, "tmass_hybrid_create: %s\n", tmass_error_string(err));
        return 1;
    }
    {
        int pre;
        tmass_qs_nodes(tmass_hybrid_precomputed_part(h), &pre);
        printf("%d tets (%d dynamic), %d nodes; precomputed %d nodes in %.1f s, %.1f MB; %d connections\n",
               mesh.tet_count, tmass_tet_count(tmass_hybrid_dynamic_part(h)), mesh.node_count, pre,
               (double)clock() / CLOCKS_PER_SEC - t0,
               tmass_qs_memory_bytes(tmass_hybrid_precomputed_part(h)) / 1048576.0,
               tmass_hybrid_connection_count(h));
    }
    printf("t [s]  tool push [mm]  tool force [N]  cut tets  connections  ms/update\n");
    for (step = 1; step <= steps; step++) {
        double now = step * DT, c0;
        tmass_real push[3] = {0, 0, 0}, f[3];
        int count = 0;
        /* the tool pushes the underside of the precomputed part up and down */
        push[2] = (tmass_real)(0.008 * (1.0 - cos(2.0 * 3.14159265358979 * now)) / 2.0);
        err = tmass_hybrid_set_displacement(h, tool, push);
        /* the scalpel moves along y = 0 through the dynamic lobe, from its tip inwards */
        for (t = 0; t < mesh.tet_count; t++)
            if (dynamic[t] && fabs(centroid(&mesh, t, 1)) < 0.45 * 2 * radii[1] / cells &&
                centroid(&mesh, t, 0) > radii[0] - 0.06 * now)
                cut[count++] = t;
        c0 = (double)clock() / CLOCKS_PER_SEC;
        if (!err) err = tmass_hybrid_remove_tets(h, cut, count, NULL); /* removed ones are skipped */
        if (!err) err = tmass_hybrid_step(h);
        seconds += (double)clock() / CLOCKS_PER_SEC - c0;
        if (err) {
            fprintf(stderr, "step %d: %s\n", step, tmass_error_string(err));
            break;
        }
        if (step % 10 == 0) {
            if (write_frame(dir, frame, h, &mesh, dynamic, live)) {
                err = 1;
                break;
            }
            frame++;
        }
        if (step % 25 == 0) {
            tmass_hybrid_contact_force(h, tool, f);
            printf("%5.2f  %14.2f  %14.3f  %8d  %11d  %9.2f\n", now, 1000.0 * push[2],
                   sqrt((double)(f[0] * f[0] + f[1] * f[1] + f[2] * f[2])),
                   tmass_tet_count(tmass_hybrid_dynamic_part(h)) - tmass_live_tet_count(tmass_hybrid_dynamic_part(h)),
                   tmass_hybrid_connection_count(h), 1000.0 * seconds / step);
        }
    }
    if (!err) printf("%d VTK frames written to %s/tensormass_hybrid_*.vtk\n", frame, dir);
    tmass_hybrid_destroy(h);
    free(rest);
    free(dynamic);
    free(fixed);
    free(live);
    free(cut);
    tetmesh_free(&mesh);
    if (fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, "tensormass_hybrid: writing to standard output failed\n");
        return 1;
    }
    return err ? 1 : 0;
}
