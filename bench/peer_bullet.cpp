/* peer_bullet.cpp - a peer in the bench (issue 21): Bullet's deformable-body Neo-Hookean and
   corotated forces and its implicit step, timed by the kernels part on the bench's own
   meshes, next to the headers' rows. Built only when Debian's libbullet-dev is installed
   (pkg-config bullet; the Makefile says how to install it otherwise) and linked only into
   the bench: the library headers never see it. Bullet is built in single precision
   (Debian: btScalar is float), so its rows say "float".

   Kernels: force = btSoftBody::updateDeformation (F of every tetrahedron) plus the force's
   addScaledElasticForce (the elastic force alone, no damping); K*v = the Neo-Hookean
   force's addScaledElasticForceDifferential at that state (corotated has none); move (the
   slot the bench uses for a model's step row here, see bench.c) = one
   btDeformableMultiBodyDynamicsWorld::stepSimulation of 1 ms, implicit (Bullet's Newton
   with its conjugate gradient), gravity on, no contact. */
#include <btBulletDynamicsCommon.h>
#include <BulletSoftBody/btDeformableBodySolver.h>
#include <BulletSoftBody/btDeformableCorotatedForce.h>
#include <BulletSoftBody/btDeformableMultiBodyConstraintSolver.h>
#include <BulletSoftBody/btDeformableMultiBodyDynamicsWorld.h>
#include <BulletSoftBody/btDeformableNeoHookeanForce.h>
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <stdlib.h>
#define TETMESH_STATIC
#define TETMESH_IMPLEMENTATION
#include "../examples/tetmesh.h"
extern "C" {
#include "bench.h"
}
#include "body_mesh.h"

namespace {

struct bt_sim {
    btSoftBodyRigidBodyCollisionConfiguration *config;
    btCollisionDispatcher *dispatcher;
    btDbvtBroadphase *broadphase;
    btDeformableBodySolver *body_solver;
    btDeformableMultiBodyConstraintSolver *solver;
    btDeformableMultiBodyDynamicsWorld *world;
    btSoftBody *body;
    btDeformableLagrangianForce *force;
    btAlignedObjectArray<btVector3> f, dx, df;
    int nodes, tets, corotated;
};

int bt_create(const bench_body *b, int corotated, void **out)
{
    tetmesh mesh;
    *out = NULL;
    if (bench_body_mesh(b, &mesh)) return -1;
    bt_sim *s = new bt_sim();
    s->config = new btSoftBodyRigidBodyCollisionConfiguration();
    s->dispatcher = new btCollisionDispatcher(s->config);
    s->broadphase = new btDbvtBroadphase();
    s->body_solver = new btDeformableBodySolver();
    s->solver = new btDeformableMultiBodyConstraintSolver();
    s->solver->setDeformableSolver(s->body_solver);
    s->world = new btDeformableMultiBodyDynamicsWorld(s->dispatcher, s->broadphase, s->solver, s->config, s->body_solver);
    btVector3 g((btScalar)b->gravity[0], (btScalar)b->gravity[1], (btScalar)b->gravity[2]);
    s->world->setGravity(g);
    s->world->getWorldInfo().m_gravity = g;
    s->world->setImplicit(true);
    btAlignedObjectArray<btVector3> x;
    btAlignedObjectArray<btScalar> mass;
    x.resize(mesh.node_count);
    mass.resize(mesh.node_count, 1);
    for (int i = 0; i < mesh.node_count; i++)
        x[i] = btVector3((btScalar)mesh.nodes[3 * i], (btScalar)mesh.nodes[3 * i + 1], (btScalar)mesh.nodes[3 * i + 2]);
    s->body = new btSoftBody(&s->world->getWorldInfo(), mesh.node_count, &x[0], &mass[0]);
    for (int t = 0; t < mesh.tet_count; t++)
        s->body->appendTetra(mesh.tets[4 * t], mesh.tets[4 * t + 1], mesh.tets[4 * t + 2], mesh.tets[4 * t + 3]);
    s->body->initializeDmInverse();
    s->body->m_tetraScratches.resize(s->body->m_tetras.size());
    s->body->m_tetraScratchesTn.resize(s->body->m_tetras.size());
    s->body->setVolumeDensity((btScalar)b->density);
    s->body->m_cfg.collisions = 0;
    s->world->addSoftBody(s->body);
    double mu = b->young / (2 * (1 + b->poisson)), lambda = b->young * b->poisson / ((1 + b->poisson) * (1 - 2 * b->poisson));
    if (corotated) s->force = new btDeformableCorotatedForce((btScalar)mu, (btScalar)lambda);
    else s->force = new btDeformableNeoHookeanForce((btScalar)mu, (btScalar)lambda, 0);
    s->world->addForce(s->body, s->force);
    for (int i = 0; i < mesh.node_count; i++) s->body->m_nodes[i].index = i;
    s->nodes = mesh.node_count;
    s->tets = mesh.tet_count;
    s->corotated = corotated;
    s->f.resize(s->nodes, btVector3(0, 0, 0));
    s->df.resize(s->nodes, btVector3(0, 0, 0));
    s->dx.resize(s->nodes);
    for (int i = 0; i < s->nodes; i++) /* the bench's direction pattern is not needed: any fixed one */
        s->dx[i] = btVector3((btScalar)((i * 7919 % 1000) * 1e-3 - 0.5), (btScalar)((i * 104729 % 1000) * 1e-3 - 0.5),
                             (btScalar)((i * 1299709 % 1000) * 1e-3 - 0.5));
    tetmesh_free(&mesh);
    *out = s;
    return 0;
}

int bt_create_nh(const bench_body *b, void **out) { return bt_create(b, 0, out); }
int bt_create_corotated(const bench_body *b, void **out) { return bt_create(b, 1, out); }

void bt_destroy(void *v)
{
    bt_sim *s = (bt_sim *)v;
    if (!s) return;
    s->world->removeSoftBody(s->body);
    delete s->body;
    delete s->force;
    delete s->world;
    delete s->solver;
    delete s->body_solver;
    delete s->broadphase;
    delete s->dispatcher;
    delete s->config;
    delete s;
}

int bt_dof(void *v)
{
    (void)bench_body_clamped; /* (body_mesh.h's, unused here) */
    return 3 * ((bt_sim *)v)->nodes;
}
int bt_node_count(void *v) { return ((bt_sim *)v)->nodes; }
void bt_rest(void *, int, double p[3]) { p[0] = p[1] = p[2] = 0; }
void bt_position(void *v, int i, double p[3])
{
    const btVector3 &x = ((bt_sim *)v)->body->m_nodes[i].m_x;
    p[0] = x.x(), p[1] = x.y(), p[2] = x.z();
}
int bt_pin(void *, int, const double *, const double *) { return BENCH_UNSUPPORTED; }
int bt_release(void *, int) { return BENCH_UNSUPPORTED; }
int bt_set_gravity(void *, const double *) { return BENCH_UNSUPPORTED; }
int bt_solve_static(void *) { return BENCH_UNSUPPORTED; }
int bt_step(void *v, double dt, int integrator)
{
    if (integrator != BENCH_IMPLICIT_EULER) return BENCH_UNSUPPORTED;
    bt_sim *s = (bt_sim *)v;
    s->world->stepSimulation((btScalar)dt, 0);
    return 0;
}
int bt_forces(void *, double *) { return BENCH_UNSUPPORTED; }
double bt_elements(void *v) { return (double)((bt_sim *)v)->tets; }
double bt_kernel_bytes(void *, int) { return 0; /* Bullet states none */ }

int bt_kernel(void *v, int kernel)
{
    bt_sim *s = (bt_sim *)v;
    if (kernel == BENCH_KERNEL_FORCE) {
        for (int i = 0; i < s->nodes; i++) s->f[i].setZero();
        s->body->updateDeformation();
        if (s->corotated) ((btDeformableCorotatedForce *)s->force)->addScaledElasticForce(1, s->f);
        else ((btDeformableNeoHookeanForce *)s->force)->addScaledElasticForce(1, s->f);
        return 0;
    }
    if (kernel == BENCH_KERNEL_KV && !s->corotated) {
        for (int i = 0; i < s->nodes; i++) s->df[i].setZero();
        ((btDeformableNeoHookeanForce *)s->force)->addScaledElasticForceDifferential(1, s->dx, s->df);
        return 0;
    }
    if (kernel == BENCH_KERNEL_STEP) {
        s->world->stepSimulation((btScalar)1e-3, 0);
        return 0;
    }
    return BENCH_UNSUPPORTED;
}

const bench_model bt_models[] = {
    {"bullet", "neo-hookean", "neo-hookean", "float", 1u << BENCH_IMPLICIT_EULER, 1, 1, "tet", bt_create_nh,
     bt_destroy, bt_dof, bt_node_count, bt_rest, bt_position, bt_pin, bt_release, bt_set_gravity, bt_solve_static,
     bt_step, bt_forces, NULL, bt_elements, bt_kernel_bytes, bt_kernel, NULL, NULL, NULL},
    {"bullet", "corotated", "linear", "float", 1u << BENCH_IMPLICIT_EULER, 1, 1, "tet", bt_create_corotated,
     bt_destroy, bt_dof, bt_node_count, bt_rest, bt_position, bt_pin, bt_release, bt_set_gravity, bt_solve_static,
     bt_step, bt_forces, NULL, bt_elements, bt_kernel_bytes, bt_kernel, NULL, NULL, NULL},
};

} // namespace

extern "C" const bench_model *bench_models_bullet(int *count);
extern "C" const bench_model *bench_models_bullet(int *count)
{
    *count = (int)(sizeof bt_models / sizeof bt_models[0]);
    return bt_models;
}
