/* render.h - the viewer's drawing, OpenGL 3.3 core through its own function loader (no
   GLAD/GLEW): every batch is an array of vertices of 9 floats (position, normal, colour),
   drawn with one shader, lit (triangles: |n . light|) or flat (lines, points). */
#ifndef VW_RENDER_H
#define VW_RENDER_H

enum { VW_TRIANGLES = 0, VW_LINES = 1, VW_POINTS = 2 };
#define VW_VERTEX_FLOATS 9

typedef void (*vw_gl_proc)(void);
typedef vw_gl_proc (*vw_gl_loader)(const char *name);

/* Loads the GL functions (glfwGetProcAddress), compiles the shader; 0, or -1 with a
   message in err[256]. Needs a current OpenGL 3.3 core context. */
int vw_render_init(vw_gl_loader load, char *err);
/* Clears the framebuffer (width x height pixels) and sets the fill mode. */
void vw_render_begin(int width, int height, int wireframe);
/* Triangles filled (0) or as their edges (1). */
void vw_render_wireframe(int on);
/* Draws `count` vertices; mvp column-major; light: direction towards the light (lit). */
void vw_render_batch(int primitive, const float *vertices, int count, const float mvp[16], const float light[3],
                     int lit, float point_size);
/* Reads the framebuffer into rgb (3 bytes per pixel, top row first). */
void vw_render_read(int width, int height, unsigned char *rgb);
void vw_render_shutdown(void);

#endif
