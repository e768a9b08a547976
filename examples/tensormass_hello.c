/* tensormass_hello.c - the minimal program of tensormass.h's manual and the README:
   a cube of six tetrahedra hanging from its top face for one simulated second, plus the
   checks every example makes (arguments, step errors, the printout). Runs in about 5 ms.
   Build: cc examples/tensormass_hello.c -lm
   Exit status 0, 1 when a step fails or the printout cannot be written, 2 for an
   argument (it takes none). */
#define TENSORMASS_IMPLEMENTATION
#include "../tensormass.h"
#include <stdio.h>

int main(int argc, char **argv)
{
    static const tmass_real nodes[8 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0,
                                            0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1};
    static const int tets[6 * 4] = {0, 1, 3, 7, 0, 5, 1, 7, 0, 3, 2, 7,
                                    0, 2, 6, 7, 0, 4, 5, 7, 0, 6, 4, 7};
    tmass_desc d = tmass_default_desc();
    tmass_model *m;
    int i, err;
    (void)argv;
    if (argc > 1) {
        fprintf(stderr, "usage: tensormass_hello (no arguments)\n");
        return 2;
    }
    d.rest_positions = nodes;
    d.node_count = 8;
    d.tets = tets;
    d.tet_count = 6;
    d.young_modulus = 1e5; // Pa
    d.poisson_ratio = 0.3;
    d.density = 1000;      // kg/m^3
    d.time_step = 1e-3;    // s
    d.integrator = TMASS_IMPLICIT_EULER;
    err = tmass_create(&d, &m);
    if (err) {
        fprintf(stderr, "%s\n", tmass_error_string(err));
        return 1;
    }
    for (i = 4; i < 8; i++) tmass_fix_node(m, i);        // the face z = 1
    for (i = 0; i < 1000 && !err; i++) err = tmass_step(m); // one simulated second
    if (err) fprintf(stderr, "step %d: %s\n", i, tmass_error_string(err));
    else printf("corner 0 sagged to z = %g m\n", (double)tmass_positions(m)[2]);
    tmass_destroy(m);
    if (fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, "tensormass_hello: writing to standard output failed\n");
        return 1;
    }
    return err ? 1 : 0;
}
