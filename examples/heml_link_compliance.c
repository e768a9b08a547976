/* heml_link_compliance.c - the 6x6 compliance of a soft arm's intervertebra from a heml.h
   tetrahedral mesh (Bosman 2015, eqs. 5.1-5.11; issue 15), the input frames.h's reduced
   chain (frm_chain_desc.compliances) takes per link. A silicone cylinder segment (radius 20
   mm, 60 mm long, E = 1 MPa, nu = 0.45) between two rigid vertebrae: the nodes of its
   face z = 0 are held, the nodes of its face z = l move rigidly with a virtual frame at the
   face's centre. Six small imposed rigid motions (three translations, three rotations of
   1e-6 of the length), each a static solve of heml.h, and the reactions on the moving face
   reduced to the frame (force and torque about its origin) give the condensed stiffness
   K_red, column by column; C = K_red^-1. Prints C (axes of the mesh: the cylinder along z)
   and the Euler-Bernoulli values of a free cylinder for comparison (the rigid faces hold the
   ends' Poisson contraction: the axial compliance comes out lower). The two headers do not
   include each other: this program includes heml.h only, and hands C to frames.h as 36
   numbers (reorder the axes to frames.h's chain, which runs along each link's local x).

       cc -O2 examples/heml_link_compliance.c -lm && ./a.out

   Runs in about a second. Exit status 0, 1 when a solve fails or the printout cannot be
   written, 2 for an argument. */
#define HEML_IMPLEMENTATION
#include "../heml.h"
#define TETMESH_IMPLEMENTATION
#include "tetmesh.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define PI 3.14159265358979323846

/* Inverse of a 6x6 matrix by Gauss-Jordan with partial pivoting; 0 or -1 (singular). */
static int invert6(const double *A, double *out)
{
    double M[6][12];
    int i, j, k;
    for (i = 0; i < 6; i++)
        for (j = 0; j < 12; j++) M[i][j] = j < 6 ? A[6 * i + j] : (j - 6 == i);
    for (k = 0; k < 6; k++) {
        int p = k;
        double t;
        for (i = k + 1; i < 6; i++)
            if (fabs(M[i][k]) > fabs(M[p][k])) p = i;
        if (M[p][k] == 0) return -1;
        for (j = 0; j < 12; j++) t = M[k][j], M[k][j] = M[p][j], M[p][j] = t;
        t = M[k][k];
        for (j = 0; j < 12; j++) M[k][j] /= t;
        for (i = 0; i < 6; i++)
            if (i != k) {
                t = M[i][k];
                for (j = 0; j < 12; j++) M[i][j] -= t * M[k][j];
            }
    }
    for (i = 0; i < 6; i++)
        for (j = 0; j < 6; j++) out[6 * i + j] = M[i][j + 6];
    return 0;
}

int main(int argc, char **argv)
{
    double r = 0.02, l = 0.06, E = 1e6, nu = 0.45, eps = 1e-6 * l, K[36], C[36];
    tetmesh mesh;
    heml_desc d = heml_default_desc();
    heml_model *m = NULL;
    heml_real *rest;
    int i, k, j, err;
    (void)argv;
    if (argc > 1) {
        fprintf(stderr, "usage: heml_link_compliance\n");
        return 2;
    }
    err = tetmesh_cylinder(&mesh, r, l, 3, 16, 6);
    if (err) {
        fprintf(stderr, "heml_link_compliance: mesh: %s\n", tetmesh_error_string(err));
        return 1;
    }
    rest = (heml_real *)malloc(sizeof(heml_real) * 3 * (size_t)mesh.node_count);
    for (i = 0; i < 3 * mesh.node_count; i++) rest[i] = (heml_real)mesh.nodes[i];
    d.rest_positions = rest;
    d.node_count = mesh.node_count;
    d.tets = mesh.tets;
    d.tet_count = mesh.tet_count;
    d.material = heml_material_from_young(HEML_NEO_HOOKEAN, E, nu);
    d.gravity[0] = d.gravity[1] = d.gravity[2] = 0;
    err = heml_create(&d, &m);
    for (k = 0; k < 6 && !err; k++) { /* imposed unit rigid motion k of the face z = l, scaled by eps */
        double F[6] = {0, 0, 0, 0, 0, 0};
        const heml_real *f;
        for (i = 0; i < mesh.node_count; i++) {
            double p[3] = {rest[3 * i], rest[3 * i + 1], rest[3 * i + 2] - l}, u[3] = {0, 0, 0};
            heml_real uu[3];
            if (fabs((double)rest[3 * i + 2]) < 1e-9 * l) {
                heml_fix_node(m, i);
                continue;
            }
            if (fabs((double)rest[3 * i + 2] - l) > 1e-9 * l) {
                heml_release_node(m, i);
                continue;
            }
            if (k < 3)
                u[k] = eps;
            else { /* eps e_(k-3) x p */
                double e[3] = {0, 0, 0};
                e[k - 3] = eps;
                u[0] = e[1] * p[2] - e[2] * p[1], u[1] = e[2] * p[0] - e[0] * p[2], u[2] = e[0] * p[1] - e[1] * p[0];
            }
            for (j = 0; j < 3; j++) uu[j] = (heml_real)u[j];
            heml_set_displacement(m, i, uu);
        }
        err = heml_solve_static(m);
        if (err) break;
        f = heml_compute_forces(m); /* elastic forces; the face's reaction is their opposite */
        for (i = 0; i < mesh.node_count; i++) {
            double p[3] = {rest[3 * i], rest[3 * i + 1], rest[3 * i + 2] - l}, R[3];
            if (fabs((double)rest[3 * i + 2] - l) > 1e-9 * l) continue;
            for (j = 0; j < 3; j++) R[j] = -(double)f[3 * i + j];
            for (j = 0; j < 3; j++) F[j] += R[j];
            F[3] += p[1] * R[2] - p[2] * R[1], F[4] += p[2] * R[0] - p[0] * R[2], F[5] += p[0] * R[1] - p[1] * R[0];
        }
        for (j = 0; j < 6; j++) K[6 * j + k] = F[j] / eps;
    }
    if (err) {
        fprintf(stderr, "heml_link_compliance: %s\n", heml_error_string(err));
        heml_destroy(m);
        free(rest);
        tetmesh_free(&mesh);
        return 1;
    }
    for (k = 0; k < 6; k++) /* symmetrise the solves' round-off */
        for (j = 0; j < k; j++) K[6 * k + j] = K[6 * j + k] = 0.5 * (K[6 * k + j] + K[6 * j + k]);
    if (invert6(K, C)) {
        fprintf(stderr, "heml_link_compliance: the condensed stiffness is singular\n");
        return 1;
    }
    printf("intervertebra: %d nodes, %d tetrahedra; compliance C (m/N, 1/N, rad/(N m); axes: cylinder along z)\n",
           mesh.node_count, mesh.tet_count);
    for (k = 0; k < 6; k++)
        printf("  %12.4e %12.4e %12.4e %12.4e %12.4e %12.4e\n", C[6 * k], C[6 * k + 1], C[6 * k + 2], C[6 * k + 3],
               C[6 * k + 4], C[6 * k + 5]);
    {
        double A = PI * r * r, I = PI * r * r * r * r / 4, G = E / (2 * (1 + nu));
        printf("Euler-Bernoulli cylinder: ux/Fx %.4e  uz/Fz %.4e  theta_x/Mx %.4e  theta_z/Mz %.4e  ux/My %.4e\n",
               l * l * l / (3 * E * I), l / (E * A), l / (E * I), l / (G * 2 * I), l * l / (2 * E * I));
    }
    heml_destroy(m);
    free(rest);
    tetmesh_free(&mesh);
    if (fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, "heml_link_compliance: writing the printout failed\n");
        return 1;
    }
    return 0;
}
