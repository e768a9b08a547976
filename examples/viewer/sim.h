/* sim.h - the viewer's one interface to the three models (sim.c), in double whatever the
   model's precision: sim.c is compiled twice, in double (vw_sim_double) and in float
   (vw_sim_float, -DVW_FLOAT), so the viewer can switch precision live on the same mesh.

   "Points" are what is drawn: the mesh nodes (tensormass, heml) or the samples (frames:
   until frames.h maps surface points, its bodies are drawn through their samples).
   "Handles" are what the mouse can grab: mesh nodes, or frames. */
#ifndef VW_SIM_H
#define VW_SIM_H

enum { VW_TENSORMASS = 0, VW_HEML = 1, VW_FRAMES = 2, VW_MODEL_COUNT = 3 };
enum { VW_EXPLICIT = 0, VW_IMPLICIT = 1, VW_IMPLICIT_LINEARIZED = 2, VW_INTEGRATOR_COUNT = 3 };
enum { VW_FIELD_DISPLACEMENT = 0, VW_FIELD_STRESS = 1, VW_FIELD_VOLUME_RATIO = 2, VW_FIELD_COUNT = 3 };

typedef struct vw_mesh {
    int node_count, tet_count;
    const double *nodes; /* 3 per node, m */
    const int *tets;     /* 4 per tetrahedron, positively oriented */
    const int *fixed;    /* nodes pinned at rest */
    int fixed_count;
    const int *boundary; /* its boundary triangles, 3 node indices each, oriented outwards */
    int boundary_count;
} vw_mesh;

typedef struct vw_config {
    int model;             /* VW_TENSORMASS, VW_HEML, VW_FRAMES */
    double young_modulus;  /* Pa */
    double poisson_ratio;
    double density;        /* kg/m^3 */
    double mass_damping;   /* 1/s */
    double frame_spacing;  /* m, frames only: least distance between frames (meshless) */
    const double *surface; /* frames from a closed surface instead of the tetrahedra: 3 per
                              vertex, or NULL */
    const int *surface_triangles;
    int surface_vertex_count, surface_triangle_count;
} vw_config;

typedef struct vw_sim vw_sim;

typedef struct vw_sim_api {
    const char *precision; /* "double" or "float" */
    /* 0 or the model's negative error code, with its message in err[256] */
    int (*create)(const vw_mesh *mesh, const vw_config *config, vw_sim **out, char *err);
    void (*destroy)(vw_sim *s);
    /* one step of dt seconds; 0 or the model's error code (message in err[256]) */
    int (*step)(vw_sim *s, double dt, int integrator, char *err);
    int (*supports)(const vw_sim *s, int integrator); /* 1 if the model has it */
    double (*stable_time_step)(const vw_sim *s);       /* s, explicit integration */
    int (*point_count)(const vw_sim *s);
    void (*points)(vw_sim *s, float *xyz);              /* current positions, 3 per point */
    int (*handle_count)(const vw_sim *s);
    void (*handle_position)(vw_sim *s, int i, double p[3]);
    int (*handle_pinned)(const vw_sim *s, int i);
    int (*drag)(vw_sim *s, int i, const double p[3]);  /* impose position p on handle i */
    int (*release)(vw_sim *s, int i);
    void (*reaction)(vw_sim *s, int i, double f[3]);   /* elastic force on handle i, N */
    /* boundary triangles of the live mesh (point indices); NULL for frames */
    const int *(*triangles)(vw_sim *s, int *count);
    /* removes tetrahedra (tensormass only; others return 1) */
    int (*cut)(vw_sim *s, const int *tets, int count, int *removed);
    int (*tear)(vw_sim *s, double max_elongation, int *removed);
    int (*tet_alive)(const vw_sim *s, int tet);
    void (*field)(vw_sim *s, int kind, float *per_point); /* colour field at each point */
    /* frames only: 12 floats per frame (origin, then x, y, z axes); returns the count */
    int (*frames)(vw_sim *s, float *out);
} vw_sim_api;

extern const vw_sim_api vw_sim_double;
extern const vw_sim_api vw_sim_float;

#endif
