/* body_mesh.h - the tetrahedral mesh of a bench_body, shared by the tet-based adapters
   (include after tetmesh.h and bench.h). */
#ifndef BENCH_BODY_MESH_H
#define BENCH_BODY_MESH_H

#include <string.h>

/* The body's box as a beam of cubic cells, 5 tets each (the split that locks least in
   bending), without the excluded region, translated by the offset. 0 or a tetmesh code. */
static int bench_body_mesh(const bench_body *b, tetmesh *mesh)
{
    int t, j, k, kept = 0, err;
    err = tetmesh_beam(mesh, b->size[0], b->size[1], b->size[2], b->cells[0], b->cells[1], b->cells[2],
                       TETMESH_SPLIT5);
    if (err) return err;
    for (t = 0; b->exclude && t < mesh->tet_count; t++) {
        double c[3] = {0, 0, 0};
        for (j = 0; j < 4; j++)
            for (k = 0; k < 3; k++) c[k] += 0.25 * mesh->nodes[3 * mesh->tets[4 * t + j] + k];
        if (!b->exclude(c, b->exclude_user)) memmove(mesh->tets + 4 * kept++, mesh->tets + 4 * t, 4 * sizeof(int));
    }
    if (b->exclude) mesh->tet_count = kept;
    for (j = 0; j < 3 * mesh->node_count; j++) mesh->nodes[j] += b->offset[j % 3];
    return 0;
}

/* 1 if rest node i (with the offset) lies on the clamped face x = 0. */
static int bench_body_clamped(const bench_body *b, const double *rest, int i)
{
    return rest[3 * i] - b->offset[0] <= 1e-9 * b->size[0];
}

#endif
