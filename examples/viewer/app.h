/* app.h - the viewer's state and the operations its input and its headless mode share
   (app.c: simulation, picking, dragging, cutting; draw.c: camera and drawing). */
#ifndef VW_APP_H
#define VW_APP_H

#include "scene.h"
#include "sim.h"

typedef struct vw_camera {
    double target[3]; /* m, the point looked at */
    double yaw, pitch; /* radians; 0, 0 looks along +y with +z up and +x to the right */
    double distance;   /* m, from the target */
    double fov;        /* radians, vertical */
} vw_camera;

typedef struct vw_app {
    vw_scene scene;
    vw_mesh mesh;
    vw_config config;
    const vw_sim_api *api;
    vw_sim *sim;
    int model, precision, integrator, field; /* precision 0 double, 1 float */
    int wireframe, tearing, paused;
    vw_camera camera;
    int width, height;          /* window size, screen coordinates (picking) */
    int fb_width, fb_height;    /* framebuffer size, pixels (drawing) */
    /* per-frame buffers */
    float *points, *values;     /* 3 per point; 1 per point */
    float *vertices;            /* render.h vertices */
    size_t vertex_capacity;     /* floats */
    float *frames;              /* 12 per frame */
    /* interaction */
    int grabbed;                /* handle being dragged, or -1 */
    double grab_start[3], grab_mouse[2], grab_target[3], grab_scale;
    int orbiting, cutting;
    double last_mouse[2];
    /* readout */
    double step_seconds, steps_per_second, dt, force[3], field_lo, field_hi;
    int steps_per_frame, removed_total;
    long frame;
    char error[256];
} vw_app;

/* app.c */
int vw_app_open(vw_app *a, char *err);     /* builds the model from scene, model, precision */
void vw_app_close(vw_app *a);              /* frees the model and buffers (not the scene) */
int vw_app_switch(vw_app *a, int model, int precision); /* rebuilds at rest; 0 or -1 */
void vw_app_advance(vw_app *a);            /* one frame (1/60 s simulated) */
int vw_app_pick(vw_app *a, double x, double y); /* nearest free handle to a screen point, or -1 */
void vw_app_grab(vw_app *a, int handle, double x, double y);
void vw_app_move_grab(vw_app *a, double x, double y);
void vw_app_pull(vw_app *a, const double offset[3]); /* the grabbed handle to its start + offset */
void vw_app_release(vw_app *a);
int vw_app_cut_segment(vw_app *a, const double p[2], const double q[2]); /* tets removed */
int vw_app_tip(const vw_app *a);            /* free handle of largest x (ties: largest z) */
void vw_app_readout(const vw_app *a, char *out, size_t size);
extern const char *const vw_model_names[VW_MODEL_COUNT];
extern const char *const vw_integrator_names[VW_INTEGRATOR_COUNT];
extern const char *const vw_field_names[VW_FIELD_COUNT];

/* draw.c */
void vw_camera_fit(vw_camera *c, const double lo[3], const double hi[3]);
/* screen position (x right, y down, in window coordinates) and view depth of p */
void vw_camera_project(const vw_app *a, const double p[3], double screen[2], double *depth);
void vw_camera_axes(const vw_camera *c, double right[3], double up[3], double forward[3]);
void vw_draw(vw_app *a);

#endif
