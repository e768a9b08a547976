/* Krylov iterations of heml_solve_static with desc.nodal_pressure = 1 or 2 against nu (issue
   13; the tables in heml.h's NEAR-INCOMPRESSIBLE BODIES and PRESSURE AGGREGATES). Not part
   of `make bench`:
       gcc -std=c99 -O2 -march=native -o build/heml_nodal_krylov bench/heml_nodal_krylov.c -lm
       build/heml_nodal_krylov 0 8 1     Cook's membrane (R10), N x N x 1 cells of six tetrahedra
       build/heml_nodal_krylov 0 16 1
       build/heml_nodal_krylov 1 4 1     beam 1 x 0.1 x 0.1, 10N x N x N cells of five, tip load
   (third argument: nodal_pressure; fourth, optional: the static solve's pressure-aggregate
   preconditioner of nodal_pressure = 2 forced off (0) or on (1) instead of its automatic
   rule, kappa >= 20 mu; an internal field). mu = 80.194 fixed, the bulk modulus from nu = 0.3,
   0.49, 0.499, 0.4999. Prints the code, the deflection, Krylov and Newton iterations, time. */
#define _POSIX_C_SOURCE 199309L
#define HEML_IMPLEMENTATION
#include "../heml.h"
#define TETMESH_IMPLEMENTATION
#include "../examples/tetmesh.h"
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
static double now(void){struct timespec t;clock_gettime(CLOCK_MONOTONIC,&t);return t.tv_sec+1e-9*t.tv_nsec;}
/* kind 0: Cook N x N x 1 split6 ; kind 1: box beam 1x0.1x0.1 N*10 x N x N split5, clamped x=0, tip load */
static int force_pc = -1;
static int run(int kind, int N, double nu, int nodal, double *uy, int *kry, int *newt, double *sec)
{
    tetmesh mesh; heml_desc d = heml_default_desc(); heml_model *m; heml_real *x;
    heml_material mt = heml_material_from_young(HEML_NEO_HOOKEAN, 1, 0.3);
    double lo[3]={0,0,0}, hi[3]={1,1,1}; int i, err, corner=-1, nt=0;
    double mu = 80.194, bulk = 2*mu*(1+nu)/(3*(1-2*nu));
    if (kind==0) { tetmesh_box(&mesh, lo, hi, N, N, 1, TETMESH_SPLIT6);
      for (i=0;i<mesh.node_count;i++){double *X=mesh.nodes+3*i,xi=X[0],eta=X[1];X[0]=48*xi;X[1]=44*xi+eta*(44-28*xi);} }
    else { hi[1]=hi[2]=0.1; tetmesh_box(&mesh, lo, hi, 10*N, N, N, TETMESH_SPLIT5); }
    mt.mu=(heml_real)mu; mt.lambda=(heml_real)(bulk-2.0/3.0*mu); mt.density=1e-9;
    d.material=mt; d.nodal_pressure=nodal; d.gravity[2]=0; d.cg_max_iterations=100000;
    x = calloc(3*mesh.node_count, sizeof *x);
    for (i=0;i<3*mesh.node_count;i++) x[i]=(heml_real)mesh.nodes[i];
    d.rest_positions=x; d.node_count=mesh.node_count; d.tets=mesh.tets; d.tet_count=mesh.tet_count;
    if (heml_create(&d,&m)) return -999;
    if (force_pc >= 0) m->pagg_pc = force_pc && m->pgt_width > 0;
    for (i=0;i<mesh.node_count;i++){ const double *X=mesh.nodes+3*i; heml_real zero[3]={0,0,0};
      if (X[0]<1e-9) heml_fix_node(m,i); else if(kind==0) heml_set_displacement_axes(m,i,4u,zero);
      if (kind==0 && X[0]>48-1e-9){double share=100.0/N/2*(X[1]<44+1e-9||X[1]>60-1e-9?0.5:1.0);heml_real f[3]={0,0,0};f[1]=(heml_real)share;heml_set_external_force(m,i,f);if(X[1]>60-1e-9&&X[2]<1e-9)corner=i;}
      if (kind==1 && X[0]>1-1e-9) nt++; }
    if (kind==1) for (i=0;i<mesh.node_count;i++){const double *X=mesh.nodes+3*i; if (X[0]>1-1e-9){heml_real f[3]={0,0,0}; f[2]=(heml_real)(-1e-5/nt); heml_set_external_force(m,i,f); if (X[1]<1e-9&&X[2]<1e-9) corner=i;}}
    { double t0=now(); err=heml_solve_static(m); *sec=now()-t0; }
    *uy=(double)heml_displacements(m)[3*corner+(kind==0?1:2)];
    *kry=heml_last_stats(m)->cg_iterations; *newt=heml_last_stats(m)->newton_iterations;
    heml_destroy(m); tetmesh_free(&mesh); free(x); return err;
}
int main(int argc, char **argv)
{
    int kind = argc>1?atoi(argv[1]):0, N = argc>2?atoi(argv[2]):8, nodal = argc>3?atoi(argv[3]):1;
    if (argc>4) force_pc = atoi(argv[4]);
    double nus[4]={0.3,0.49,0.499,0.4999}; int k;
    for (k=0;k<4;k++){ double uy,s; int kr,nw; int e=run(kind,N,nus[k],nodal,&uy,&kr,&nw,&s);
      printf("%s N=%d nodal=%d nu=%.4f err=%d u=%.6g krylov=%d newton=%d time=%.3fs\n", kind?"beam":"cook",N,nodal,nus[k],e,uy,kr,nw,s); fflush(stdout);}
    return 0;
}
