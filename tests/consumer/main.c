/* main.c - the consumer of tests/test_packaging.sh: the three headers found through the
   include path a build system gave, tensormass.h's implementation compiled here (the other
   two are declarations only, to keep the test's compile time small), one tiny model
   stepped. Prints "consumer ok <version>" and exits 0 on success. */
#define TENSORMASS_IMPLEMENTATION
#include "tensormass.h"
#include "heml.h"
#include "frames.h"
#include <stdio.h>

int main(void)
{
    static const tmass_real nodes[4 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const int tets[4] = {0, 1, 2, 3};
    tmass_desc d = tmass_default_desc();
    tmass_model *m;
    int i, err;
    d.rest_positions = nodes;
    d.node_count = 4;
    d.tets = tets;
    d.tet_count = 1;
    err = tmass_create(&d, &m);
    if (err) {
        printf("create: %s\n", tmass_error_string(err));
        return 1;
    }
    for (i = 0; i < 3; i++) tmass_fix_node(m, i);
    err = tmass_step(m);
    tmass_destroy(m);
    if (err) return 1;
    printf("consumer ok %s\n", tmass_version());
    return 0;
}
