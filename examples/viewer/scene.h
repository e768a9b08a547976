/* scene.h - what the viewer shows: a built-in scene (a cantilever, a liver-like lobe
   hanging from its ligament) or a user's mesh (TetGen .node/.ele, Gmsh .msh, or a closed
   .obj surface, which only the frames model can simulate, through its meshless sampling). */
#ifndef VW_SCENE_H
#define VW_SCENE_H

#include "../tetmesh.h"

typedef struct vw_scene {
    char name[64];
    tetmesh mesh;          /* empty for an .obj surface */
    int *fixed;            /* nodes pinned at rest */
    int fixed_count;
    int *boundary;         /* boundary triangles of the mesh */
    int boundary_count;
    double *surface;       /* .obj: 3 per vertex, m; else NULL */
    int *surface_triangles;
    int surface_vertex_count, surface_triangle_count;
    double young_modulus;  /* Pa */
    double poisson_ratio;
    double density;        /* kg/m^3 */
    double mass_damping;   /* 1/s */
    double frame_spacing;  /* m, frames from a surface */
    double lo[3], hi[3];   /* rest bounding box, m */
} vw_scene;

/* "cantilever" or "lobe"; 0, or -1 with a message in err[256]. */
int vw_scene_builtin(vw_scene *s, const char *name, char *err);
/* A mesh file: path ending in .node (with its .ele), .msh or .obj. The nodes within 2 %
   of the extent of the smallest x are pinned (the frames within one frame spacing of it
   for a surface). 0, or -1 with a message in err[256]. */
int vw_scene_load(vw_scene *s, const char *path, char *err);
void vw_scene_free(vw_scene *s);

#endif
