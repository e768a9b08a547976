/* heml_compression.c - the uniaxial compression test of Goulette & Chen sec. 5.1 (fig. 6):
   a 10 mm cube squeezed along z at a constant 1 mm/s by its top face, bottom face on
   rollers, lateral faces free, simulated with the paper's semi-explicit Euler scheme.
   Prints CSV to stdout: displacement, force on the top face (the sum of the reactions,
   f_s = P_zz S0, eq. 33) and the closed form for the same stretch (REFERENCES R4 for
   St Venant-Kirchhoff, R5 for the compressible Neo-Hookean of eq. 26). The two agree to
   0.5 % while the start-up transient dies down (first 0.1 mm), to 0.1 % after 1 mm.
   St Venant-Kirchhoff is compressed to 30 % only: near s = 0.67 its homogeneous
   compression loses stability (the law softens, sec. 4.2), the cube shears sideways and
   the force drops below the closed form. Neo-Hookean goes to 40 %.
   Build: cc examples/heml_compression.c -lm       Run: ./a.out [svk|nh] > curve.csv
   Runs in about 0.4 s (svk, the default) or 0.25 s (nh) (gcc -O2, one core of this
   project's machine). Exit status 0, 1 when a step fails or the CSV cannot be written
   (a full disk, a closed pipe), 2 for a bad argument. */
#define HEML_IMPLEMENTATION
#include "../heml.h"
#define TETMESH_IMPLEMENTATION
#include "tetmesh.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void usage(void)
{
    fprintf(stderr, "usage: heml_compression [svk|nh] > curve.csv\n");
    exit(2);
}

/* Closed-form P_zz at stretch s (R4, R5). For Neo-Hookean the lateral stretch t solves
   P_xx = mu (t - 1/t) + lambda ln(s t^2) / t = 0 (Newton). */
static double closed_form(heml_law law, double mu, double lambda, double s)
{
    double t = 1.0;
    int i;
    if (law == HEML_STVK) return mu * (3 * lambda + 2 * mu) / (2 * (lambda + mu)) * (s * s * s - s);
    for (i = 0; i < 50; i++) {
        double g = mu * (t - 1 / t) + lambda * log(s * t * t) / t;
        double dg = mu * (1 + 1 / (t * t)) + lambda * (2 - log(s * t * t)) / (t * t);
        t -= g / dg;
    }
    return mu * (s - 1 / s) + lambda * log(s * t * t) / s;
}

int main(int argc, char **argv)
{
    const double side = 0.01, speed = 1e-3; /* m, m/s */
    double lo[3] = {0, 0, 0}, hi[3] = {side, side, side}, t = 0, dt, next_print = 0;
    heml_law law = HEML_STVK;
    double squeeze;
    heml_desc d = heml_default_desc();
    heml_real *x;
    heml_model *m;
    tetmesh mesh;
    int i, err;

    if (argc > 2) usage();
    if (argc == 2 && strcmp(argv[1], "nh") == 0) law = HEML_NEO_HOOKEAN;
    else if (argc == 2 && strcmp(argv[1], "svk") != 0) usage();
    squeeze = (law == HEML_STVK ? 0.3 : 0.4) * side; /* m */
    tetmesh_box(&mesh, lo, hi, 4, 4, 4, TETMESH_SPLIT6);
    x = (heml_real *)malloc(sizeof(heml_real) * 3 * mesh.node_count);
    for (i = 0; i < 3 * mesh.node_count; i++) x[i] = (heml_real)mesh.nodes[i];
    d.rest_positions = x;
    d.node_count = mesh.node_count;
    d.tets = mesh.tets;
    d.tet_count = mesh.tet_count;
    d.material = heml_material_from_young(law, 1e4, 0.3); /* soft tissue, Pa */
    d.gravity[2] = 0;
    d.mass_damping = 200; /* 1/s: damps the elastic waves, negligible at 1 mm/s */
    err = heml_create(&d, &m);
    if (err) {
        fprintf(stderr, "%s\n", heml_error_string(err));
        return 1;
    }
    dt = heml_stable_time_step(m);

    /* rollers below (z held, one corner fully, one more in y: no rigid motion) */
    for (i = 0; i < mesh.node_count; i++) {
        const double *p = mesh.nodes + 3 * i;
        heml_real zero[3] = {0, 0, 0};
        if (p[2] == 0) heml_set_displacement_axes(m, i, p[0] == 0 && p[1] == 0 ? 7u : p[1] == 0 ? 6u : 4u, zero);
    }

    if (printf("displacement_mm,force_N,closed_form_N\n") < 0) err = 1;
    while (!err && t <= squeeze / speed) {
        double u = speed * t, force = 0;
        heml_real down[3] = {0, 0, 0};
        down[2] = (heml_real)-u;
        for (i = 0; i < mesh.node_count; i++) /* the top face follows the press */
            if (mesh.nodes[3 * i + 2] == side) heml_set_displacement_axes(m, i, 4u, down);
        err = heml_step_ex(m, (heml_real)dt, HEML_SEMI_EXPLICIT_EULER);
        if (err) {
            fprintf(stderr, "%s\n", heml_error_string(err));
            return 1;
        }
        t += dt;
        if (t >= next_print) {
            const heml_real *f = heml_compute_forces(m);
            for (i = 0; i < mesh.node_count; i++) /* the press holds -f on the top face */
                if (mesh.nodes[3 * i + 2] == side) force -= (double)f[3 * i + 2];
            if (printf("%.3f,%.6g,%.6g\n", u * 1e3, force,
                       closed_form(law, d.material.mu, d.material.lambda, 1 - u / side) * side * side) < 0)
                err = 1; /* stops the loop */
            next_print += 0.1e-3 / speed; /* every 0.1 mm */
        }
    }
    heml_destroy(m);
    tetmesh_free(&mesh);
    free(x);
    if (err || fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, "heml_compression: writing the CSV to standard output failed\n");
        return 1;
    }
    return 0;
}
