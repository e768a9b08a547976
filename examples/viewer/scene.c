/* scene.c - the built-in scenes and the mesh loaders of the viewer (scene.h). */
#define TETMESH_IMPLEMENTATION
#include "scene.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void vw__bounds(vw_scene *s, const double *x, int n)
{
    int i, k;
    for (k = 0; k < 3; k++) {
        s->lo[k] = 1e30;
        s->hi[k] = -1e30;
    }
    for (i = 0; i < n; i++)
        for (k = 0; k < 3; k++) {
            if (x[3 * i + k] < s->lo[k]) s->lo[k] = x[3 * i + k];
            if (x[3 * i + k] > s->hi[k]) s->hi[k] = x[3 * i + k];
        }
}

/* Pins the nodes for which inside(p) holds; boundary and bounds computed. */
static int vw__finish_mesh(vw_scene *s, int (*inside)(const double p[3], const vw_scene *s), char *err)
{
    int i, rc;
    vw__bounds(s, s->mesh.nodes, s->mesh.node_count);
    s->fixed = (int *)malloc(sizeof(int) * (size_t)s->mesh.node_count);
    if (!s->fixed) return snprintf(err, 256, "out of memory"), -1;
    for (i = 0; i < s->mesh.node_count; i++)
        if (inside(s->mesh.nodes + 3 * i, s)) s->fixed[s->fixed_count++] = i;
    rc = tetmesh_boundary(s->mesh.tets, s->mesh.tet_count, s->mesh.node_count, &s->boundary, &s->boundary_count);
    if (rc) return snprintf(err, 256, "boundary: %s", tetmesh_error_string(rc)), -1;
    if (s->fixed_count == 0) return snprintf(err, 256, "no node to pin"), -1;
    return 0;
}

/* the clamp of a beam, and of a user's mesh: within 2 % of the extent from the smallest x */
static int vw__at_min_x(const double p[3], const vw_scene *s)
{
    return p[0] <= s->lo[0] + 0.02 * (s->hi[0] - s->lo[0]);
}

/* the lobe's ligament: a patch on top, towards its right end */
static int vw__ligament(const double p[3], const vw_scene *s)
{
    double dx = p[0] - 0.3 * s->hi[0];
    return p[2] > s->hi[2] - 0.3 * (s->hi[2] - s->lo[2]) && fabs(dx) < 0.18 * (s->hi[0] - s->lo[0]) &&
           fabs(p[1]) < 0.25 * (s->hi[1] - s->lo[1]);
}

static void vw__material(vw_scene *s, double young, double damping)
{
    s->young_modulus = young;
    s->poisson_ratio = 0.3;
    s->density = 1000;
    s->mass_damping = damping;
}

int vw_scene_builtin(vw_scene *s, const char *name, char *err)
{
    int rc;
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "%s", name);
    if (strcmp(name, "cantilever") == 0) {
        /* 0.4 x 0.06 x 0.06 m, E = 2 MPa: about 5 cm of static sag, 2.7 Hz */
        rc = tetmesh_beam(&s->mesh, 0.4, 0.06, 0.06, 16, 3, 3, TETMESH_SPLIT5);
        vw__material(s, 2e6, 1.0);
        s->frame_spacing = 0.03;
        if (rc) return snprintf(err, 256, "%s", tetmesh_error_string(rc)), -1;
        return vw__finish_mesh(s, vw__at_min_x, err);
    }
    if (strcmp(name, "lobe") == 0) {
        /* a liver-like lobe, 24 x 14 x 9 cm, soft (E = 20 kPa), hanging from a patch on top */
        const double radii[3] = {0.12, 0.07, 0.045};
        rc = tetmesh_ellipsoid(&s->mesh, radii, 14);
        vw__material(s, 2e4, 2.0);
        s->frame_spacing = 0.03;
        if (rc) return snprintf(err, 256, "%s", tetmesh_error_string(rc)), -1;
        return vw__finish_mesh(s, vw__ligament, err);
    }
    snprintf(err, 256, "unknown scene '%s' (cantilever, lobe)", name);
    return -1;
}

static int vw__ends_with(const char *s, const char *end)
{
    size_t a = strlen(s), b = strlen(end);
    return a >= b && strcmp(s + a - b, end) == 0;
}

/* Appends one index to a growing array; -1 when out of memory. */
static int vw__push_int(int **a, int *n, int *cap, int v)
{
    if (*n == *cap) {
        int *g = (int *)realloc(*a, sizeof(int) * (size_t)(*cap = *cap ? 2 * *cap : 256));
        if (!g) return -1;
        *a = g;
    }
    (*a)[(*n)++] = v;
    return 0;
}

static int vw__push_vertex(vw_scene *s, int *cap, const double p[3])
{
    if (s->surface_vertex_count == *cap) {
        double *g = (double *)realloc(s->surface, sizeof(double) * 3 * (size_t)(*cap = *cap ? 2 * *cap : 256));
        if (!g) return -1;
        s->surface = g;
    }
    memcpy(s->surface + 3 * s->surface_vertex_count++, p, sizeof(double) * 3);
    return 0;
}

/* One "f a b c ..." line (a/t/n forms, negative indices from the end): a triangle fan. */
static int vw__obj_face(vw_scene *s, const char *line, int *tri_cap)
{
    int idx[64], n = 0, i, used, count = 3 * s->surface_triangle_count;
    long v;
    while (n < 64 && sscanf(line, " %ld%n", &v, &used) == 1) {
        line += used;
        while (*line && *line != ' ' && *line != '\t') line++; /* skip /t/n */
        idx[n] = (int)(v < 0 ? s->surface_vertex_count + v : v - 1);
        if (idx[n] < 0 || idx[n] >= s->surface_vertex_count) return -1;
        n++;
    }
    if (n < 3) return -1;
    for (i = 1; i + 1 < n; i++)
        if (vw__push_int(&s->surface_triangles, &count, tri_cap, idx[0]) ||
            vw__push_int(&s->surface_triangles, &count, tri_cap, idx[i]) ||
            vw__push_int(&s->surface_triangles, &count, tri_cap, idx[i + 1]))
            return -1;
    s->surface_triangle_count = count / 3;
    return 0;
}

static int vw__load_obj(vw_scene *s, const char *path, char *err)
{
    FILE *f = fopen(path, "r");
    char line[1024];
    int vcap = 0, tcap = 0, rc = 0, lineno = 0;
    if (!f) return snprintf(err, 256, "cannot open %s", path), -1;
    while (!rc && fgets(line, sizeof line, f)) {
        double p[3];
        lineno++;
        if (line[0] == 'v' && line[1] == ' ') {
            rc = sscanf(line + 2, "%lf %lf %lf", &p[0], &p[1], &p[2]) == 3 ? vw__push_vertex(s, &vcap, p) : -1;
        } else if (line[0] == 'f' && line[1] == ' ') rc = vw__obj_face(s, line + 2, &tcap);
    }
    fclose(f);
    if (rc) return snprintf(err, 256, "%s:%d: bad vertex or face", path, lineno), -1;
    if (s->surface_triangle_count < 4) return snprintf(err, 256, "%s: not a closed surface", path), -1;
    vw__bounds(s, s->surface, s->surface_vertex_count);
    return 0;
}

int vw_scene_load(vw_scene *s, const char *path, char *err)
{
    int rc;
    double extent;
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "%.63s", path);
    vw__material(s, 1e5, 1.0);
    if (vw__ends_with(path, ".obj")) {
        if (vw__load_obj(s, path, err)) return -1;
        extent = s->hi[0] - s->lo[0];
        if (s->hi[1] - s->lo[1] > extent) extent = s->hi[1] - s->lo[1];
        if (s->hi[2] - s->lo[2] > extent) extent = s->hi[2] - s->lo[2];
        s->frame_spacing = extent / 6;
        return 0;
    }
    if (vw__ends_with(path, ".node")) {
        char ele[1024];
        snprintf(ele, sizeof ele, "%.*s.ele", (int)strlen(path) - 5, path);
        rc = tetmesh_read_tetgen(&s->mesh, path, ele);
    } else if (vw__ends_with(path, ".msh")) rc = tetmesh_read_gmsh(&s->mesh, path);
    else return snprintf(err, 256, "%s: expected a .node, .msh or .obj file", path), -1;
    if (rc) return snprintf(err, 256, "%s: %s", path, tetmesh_error_string(rc)), -1;
    return vw__finish_mesh(s, vw__at_min_x, err);
}

void vw_scene_free(vw_scene *s)
{
    tetmesh_free(&s->mesh);
    free(s->fixed);
    free(s->boundary);
    free(s->surface);
    free(s->surface_triangles);
    memset(s, 0, sizeof *s);
}
