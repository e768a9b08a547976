/* frames_connective.c - two organs joined by a thin meshless connective layer (issue 14;
   Bosman, Duriez & Cotin 2013 fig. 5): the top organ hangs from fixed frames, a rigid
   instrument pushes the lower one up from below. Writes one VTK pair per frame and prints
   the time per step split by part.

       frames_connective [output-directory]      (default: the current directory)

   "Model only what a scene requires": each part uses the model whose strengths it needs.
   - Top organ (0.1 x 0.1 x 0.04 m, E = 20 kPa): frames.h on hexahedral frames, 4 x 4 x 2
     cells. It is the organ we hang and move as a whole; smooth, large motions are what
     frames resolve with few degrees of freedom (75 frames here), and frames give it a
     shared kind of node with the connective layer.
   - Connective layer (a 1 cm sheet, E = 2 kPa): frames.h meshless Shepard samples in the
     same model, sharing the top organ's lower frames (no mesh to make: the 2013 paper's
     layer "without prior assumption on the dimension of its geometry"), 25 own frames on
     its lower face.
   - Lower organ (0.1 x 0.1 x 0.05 m, E = 10 kPa): heml.h Neo-Hookean tetrahedra. It is the
     one the instrument deforms locally and strongly: a tetrahedral mesh resolves the local
     indentation and stays robust if tetrahedra flatten. Its top nodes are glued to the
     layer's lower face through mapped points (examples/glue.h: the stiff coupling, springs
     of 0.3 E h per node, a Robin-Neumann iteration with Anderson mixing each step). The
     springs are anchors of the frames model and loads on the mesh: the lower organ is held
     by the instrument, so its solve under given forces is well posed. (The other way round,
     springs in the mesh and loads on the layer's lower frames, the frames' first Newton
     solve did not converge here; not investigated further.)
   - Instrument: rigid, so it is not simulated at all: the lower organ's nodes under its
     flat 5 cm tip follow it (prescribed displacements), rising 6 mm over the first 0.2 s.
   Implicit Euler at dt = 10 ms in both models (the staggered exchange would need about
   1 ms here, frames.h COUPLING). */
#define FRAMES_IMPLEMENTATION
#include "../frames.h"
#define HEML_IMPLEMENTATION
#include "../heml.h"
#define TETMESH_IMPLEMENTATION
#include "tetmesh.h"
#include "glue.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define NX 4    /* cells across (x and y), both organs */
#define STEPS 25
#define DT 0.01 /* s */

static void usage(void)
{
    fprintf(stderr, "usage: frames_connective [output-directory]\n");
    exit(2);
}

static int writable(const char *dir)
{
    char path[512];
    FILE *f;
    snprintf(path, sizeof path, "%s/.frames_connective_probe", dir);
    f = fopen(path, "w");
    if (!f) return 0;
    fclose(f);
    remove(path);
    return 1;
}

/* The frames model: the top organ's hexahedral part and the layer's meshless part sharing
   the organ's lower frames. Frames 0..74: the organ's grid nodes (i + 5 (j + 5 k)), z from
   0.06 to 0.10 m; 75..99 the layer's lower face at z = 0.05 m. */
static int build_frames(frm_model **m, frm_probe_desc *pd)
{
    frm_sampling organ, layer;
    frm_part parts[2];
    frm_assembly as;
    frm_desc d = frm_model_default_desc();
    const double lo[3] = {0, 0, 0.06}, hi[3] = {0.1, 0.1, 0.10};
    hexmesh grid;
    frm_real *nodes, fx[3 * 50], sx[3 * 8 * 8 * 2];
    int map[50], i, j, k, ns = 0, err;
    if (hexmesh_grid(&grid, lo, hi, NX, NX, 2) != TETMESH_OK) return FRM_ERR_ALLOC;
    nodes = (frm_real *)malloc(sizeof(frm_real) * 3 * (size_t)grid.node_count);
    for (i = 0; i < 3 * grid.node_count; i++) nodes[i] = (frm_real)grid.nodes[i];
    err = frm_sampling_hexes(&organ, nodes, grid.node_count, grid.hexes, grid.hex_count, 2, FRM_QUADRATURE_SUBCELL, NULL);
    free(nodes);
    hexmesh_free(&grid);
    if (err) return err;
    for (i = 0; i < 50; i++) { /* the layer's frames: the organ's lower face, then a copy 1 cm below */
        int node = i % 25;
        for (k = 0; k < 3; k++) fx[3 * i + k] = organ.frame_positions[3 * node + k];
        if (i >= 25) fx[3 * i + 2] = (frm_real)0.05;
        map[i] = i < 25 ? node : 75 + (i - 25);
    }
    for (i = 0; i < 8; i++) /* the layer's samples: 8 x 8 x 2 cell centres */
        for (j = 0; j < 8; j++)
            for (k = 0; k < 2; k++, ns++) {
                sx[3 * ns] = (frm_real)(0.00625 + 0.0125 * i);
                sx[3 * ns + 1] = (frm_real)(0.00625 + 0.0125 * j);
                sx[3 * ns + 2] = (frm_real)(0.0525 + 0.005 * k);
            }
    *pd = frm_probe_default_desc(); /* mapped points on the layer: its own meshless shape functions */
    err = frm_sampling_meshless(&layer, fx, 50, sx, ns, (frm_real)(0.1 * 0.1 * 0.01), &pd->shape, NULL);
    if (err) {
        frm_sampling_free(&organ);
        return err;
    }
    parts[0] = frm_part_default();
    parts[1] = frm_part_default();
    parts[0].sampling = &organ;
    parts[0].material.law = FRM_LAW_NEO_HOOKEAN;
    parts[0].material.young_modulus = (frm_real)2e4;
    parts[0].material.poisson_ratio = (frm_real)0.4;
    parts[1].sampling = &layer;
    parts[1].frame_map = map;
    parts[1].material.law = FRM_LAW_NEO_HOOKEAN;
    parts[1].material.young_modulus = (frm_real)2e3;
    parts[1].material.poisson_ratio = (frm_real)0.4;
    err = frm_parts_combine(&as, parts, 2, NULL, 0, 100, NULL);
    frm_sampling_free(&organ);
    frm_sampling_free(&layer);
    if (err) return err;
    frm_assembly_apply(&as, &d);
    d.time_step = (frm_real)DT;
    d.mass_damping = (frm_real)2;
    err = frm_model_create(&d, m);
    frm_assembly_free(&as);
    if (err) return err;
    for (i = 0; i < 100; i++) /* hanging: the organ's top face is held */
        if (frm_model_rest_positions(*m)[3 * i + 2] > (frm_real)0.0999) frm_model_fix_frame(*m, i);
    return FRM_OK;
}

int main(int argc, char **argv)
{
    const char *dir = ".";
    char path[512];
    const double lo[3] = {0, 0, 0}, hi[3] = {0.1, 0.1, 0.05};
    tetmesh mesh;
    heml_desc hd = heml_default_desc();
    heml_model *h = NULL;
    frm_model *f = NULL;
    frm_probe_desc pd;
    glue gl;
    heml_real *rest;
    int *glued, *pushed, ng = 0, np = 0, i, step, err, iterations = 0;
    double total = 0;

    if (argc > 2 || (argc == 2 && argv[1][0] == '-')) usage();
    if (argc == 2) dir = argv[1];
    if (!writable(dir)) {
        fprintf(stderr, "frames_connective: cannot write in directory '%s'\n", dir);
        return 1;
    }
    err = build_frames(&f, &pd);
    if (err) {
        fprintf(stderr, "frames_connective: frames model: %s\n", frm_error_string(err));
        return 1;
    }
    if (tetmesh_box(&mesh, lo, hi, NX, NX, 3, TETMESH_SPLIT6) != TETMESH_OK) return 1;
    rest = (heml_real *)malloc(sizeof(heml_real) * 3 * (size_t)mesh.node_count);
    for (i = 0; i < 3 * mesh.node_count; i++) rest[i] = (heml_real)mesh.nodes[i];
    hd.rest_positions = rest;
    hd.node_count = mesh.node_count;
    hd.tets = mesh.tets;
    hd.tet_count = mesh.tet_count;
    hd.material = heml_material_from_young(HEML_NEO_HOOKEAN, 1e4, 0.4);
    hd.mass_damping = 2;
    hd.integrator = HEML_IMPLICIT_EULER;
    hd.time_step = (heml_real)DT;
    err = heml_create(&hd, &h);
    free(rest);
    if (err) {
        fprintf(stderr, "frames_connective: heml model: %s\n", heml_error_string(err));
        return 1;
    }
    glued = (int *)malloc(sizeof(int) * (size_t)mesh.node_count);
    pushed = (int *)malloc(sizeof(int) * (size_t)mesh.node_count);
    for (i = 0; i < mesh.node_count; i++) {
        const double *x = mesh.nodes + 3 * i;
        if (x[2] > 0.0499) glued[ng++] = i; /* the top face: glued to the layer */
        if (x[2] < 1e-9 && fabs(x[0] - 0.05) <= 0.026 && fabs(x[1] - 0.05) <= 0.026) pushed[np++] = i;
    }
    err = glue_init_heml(&gl, h, f, &pd, glued, ng, 0.3 * 1e4 * (0.1 / NX));
    if (err) {
        fprintf(stderr, "frames_connective: glue: %s\n", frm_error_string(err));
        return 1;
    }
    gl.depth = GLUE_DEPTH;
    gl.robin_frames = 1; /* the springs in the frames model (anchors), their forces on the mesh */
    printf("frames: %d frames, %d samples; heml: %d nodes, %d tetrahedra; %d glued nodes, %d under the "
           "instrument\n",
           frm_model_frame_count(f), frm_model_sample_count(f), heml_node_count(h), heml_tet_count(h), ng, np);
    for (step = 0; step < STEPS; step++) {
        double t = (step + 1) * DT, lift = 0.006 * (t < 0.2 ? t / 0.2 : 1.0);
        clock_t t0 = clock();
        for (i = 0; i < np; i++) { /* the rigid instrument's flat tip */
            heml_real u[3] = {0, 0, 0};
            u[2] = (heml_real)lift;
            heml_set_displacement(h, pushed[i], u);
        }
        err = glue_solve(&gl, DT, 1e-7, 40);
        total += (double)(clock() - t0) / CLOCKS_PER_SEC;
        if (err) {
            fprintf(stderr, "frames_connective: step %d: %s\n", step,
                    glue_error_string(&gl, err));
            return 1;
        }
        iterations += gl.iterations;
        snprintf(path, sizeof path, "%s/frames_connective_lower_%03d.vtk", dir, step);
        err = tetmesh_write_vtk(path, heml_positions(h), TETMESH_TYPE_OF(heml_real), heml_node_count(h), mesh.tets,
                                mesh.tet_count, NULL, 0);
        if (!err) {
            snprintf(path, sizeof path, "%s/frames_connective_frames_%03d.vtk", dir, step);
            err = tetmesh_write_vtk(path, frm_model_positions(f), TETMESH_TYPE_OF(frm_real), frm_model_frame_count(f), NULL,
                                    0, NULL, 0);
        }
        if (err) {
            fprintf(stderr, "frames_connective: cannot write %s: %s\n", path, tetmesh_error_string(err));
            return 1;
        }
    }
    printf("%d steps of %.0f ms: %.2f coupling iterations a step; per step %.1f ms: frames (top organ and layer) "
           "%.1f ms, heml (lower organ) %.1f ms, exchange %.1f ms\n",
           STEPS, 1e3 * DT, (double)iterations / STEPS, 1e3 * total / STEPS, 1e3 * gl.frames_seconds / STEPS,
           1e3 * gl.mesh_seconds / STEPS, 1e3 * (total - gl.frames_seconds - gl.mesh_seconds) / STEPS);
    printf("instrument lift 6.0 mm; lower organ's top centre rose %.2f mm; top organ's lower centre %.2f mm\n",
           1e3 * ((double)heml_positions(h)[3 * glued[ng / 2] + 2] - 0.05),
           1e3 * (double)frm_model_displacements(f)[3 * 12 + 2]);
    printf("%d VTK frames written to %s (frames_connective_lower_*.vtk, frames_connective_frames_*.vtk)\n", STEPS, dir);
    glue_free(&gl);
    free(glued);
    free(pushed);
    tetmesh_free(&mesh);
    heml_destroy(h);
    frm_model_destroy(f);
    if (fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, "frames_connective: writing to standard output failed\n");
        return 1;
    }
    return 0;
}
