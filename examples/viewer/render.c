/* render.c - OpenGL 3.3 core drawing for the viewer (render.h): the function loader, one
   shader, one vertex buffer refilled per batch. */
#include "render.h"
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#ifdef _WIN32
#define VW_APIENTRY __stdcall
#else
#define VW_APIENTRY
#endif

typedef unsigned int GLenum;
typedef unsigned int GLuint;
typedef unsigned int GLbitfield;
typedef int GLint;
typedef int GLsizei;
typedef float GLfloat;
typedef char GLchar;
typedef unsigned char GLboolean;
typedef ptrdiff_t GLsizeiptr;

#define GL_DEPTH_BUFFER_BIT 0x0100
#define GL_COLOR_BUFFER_BIT 0x4000
#define GL_POINTS 0x0000
#define GL_LINES 0x0001
#define GL_TRIANGLES 0x0004
#define GL_DEPTH_TEST 0x0B71
#define GL_FRONT_AND_BACK 0x0408
#define GL_LINE 0x1B01
#define GL_FILL 0x1B02
#define GL_PACK_ALIGNMENT 0x0D05
#define GL_RGB 0x1907
#define GL_UNSIGNED_BYTE 0x1401
#define GL_FLOAT 0x1406
#define GL_ARRAY_BUFFER 0x8892
#define GL_STREAM_DRAW 0x88E0
#define GL_FRAGMENT_SHADER 0x8B30
#define GL_VERTEX_SHADER 0x8B31
#define GL_COMPILE_STATUS 0x8B81
#define GL_LINK_STATUS 0x8B82
#define GL_PROGRAM_POINT_SIZE 0x8642
#define GL_POLYGON_OFFSET_FILL 0x8037

/* The functions the viewer calls: return type, name, parameters. */
#define VW_GL_FUNCTIONS(X)                                                                         \
    X(void, Clear, (GLbitfield mask))                                                              \
    X(void, ClearColor, (GLfloat r, GLfloat g, GLfloat b, GLfloat a))                              \
    X(void, Enable, (GLenum cap))                                                                  \
    X(void, Viewport, (GLint x, GLint y, GLsizei w, GLsizei h))                                    \
    X(void, PolygonMode, (GLenum face, GLenum mode))                                               \
    X(void, PolygonOffset, (GLfloat factor, GLfloat units))                                        \
    X(void, DrawArrays, (GLenum mode, GLint first, GLsizei count))                                 \
    X(void, PixelStorei, (GLenum name, GLint value))                                               \
    X(void, ReadPixels, (GLint x, GLint y, GLsizei w, GLsizei h, GLenum f, GLenum t, void *data))  \
    X(void, Finish, (void))                                                                        \
    X(GLuint, CreateShader, (GLenum type))                                                         \
    X(void, ShaderSource, (GLuint s, GLsizei n, const GLchar *const *text, const GLint *len))     \
    X(void, CompileShader, (GLuint s))                                                             \
    X(void, GetShaderiv, (GLuint s, GLenum name, GLint *value))                                    \
    X(void, GetShaderInfoLog, (GLuint s, GLsizei size, GLsizei *len, GLchar *log))                 \
    X(void, DeleteShader, (GLuint s))                                                              \
    X(GLuint, CreateProgram, (void))                                                               \
    X(void, AttachShader, (GLuint p, GLuint s))                                                    \
    X(void, LinkProgram, (GLuint p))                                                               \
    X(void, GetProgramiv, (GLuint p, GLenum name, GLint *value))                                   \
    X(void, GetProgramInfoLog, (GLuint p, GLsizei size, GLsizei *len, GLchar *log))                \
    X(void, UseProgram, (GLuint p))                                                                \
    X(void, DeleteProgram, (GLuint p))                                                             \
    X(GLint, GetUniformLocation, (GLuint p, const GLchar *name))                                   \
    X(void, UniformMatrix4fv, (GLint at, GLsizei n, GLboolean transpose, const GLfloat *v))        \
    X(void, Uniform3fv, (GLint at, GLsizei n, const GLfloat *v))                                   \
    X(void, Uniform1f, (GLint at, GLfloat v))                                                      \
    X(void, GenVertexArrays, (GLsizei n, GLuint *out))                                             \
    X(void, BindVertexArray, (GLuint a))                                                           \
    X(void, DeleteVertexArrays, (GLsizei n, const GLuint *a))                                      \
    X(void, GenBuffers, (GLsizei n, GLuint *out))                                                  \
    X(void, BindBuffer, (GLenum target, GLuint b))                                                 \
    X(void, BufferData, (GLenum target, GLsizeiptr size, const void *data, GLenum usage))          \
    X(void, DeleteBuffers, (GLsizei n, const GLuint *b))                                           \
    X(void, EnableVertexAttribArray, (GLuint i))                                                   \
    X(void, VertexAttribPointer, (GLuint i, GLint n, GLenum t, GLboolean norm, GLsizei stride,     \
                                  const void *offset))

#define VW_GL_DECLARE(ret, name, params) ret(VW_APIENTRY *name) params;
typedef struct vw_gl {
    VW_GL_FUNCTIONS(VW_GL_DECLARE)
} vw_gl;

static vw_gl gl;
static GLuint vw__program, vw__vao, vw__vbo;
static GLint vw__u_mvp, vw__u_light, vw__u_lit, vw__u_point;

static const char *vw__vertex_shader =
    "#version 330 core\n"
    "layout(location = 0) in vec3 position;\n"
    "layout(location = 1) in vec3 normal;\n"
    "layout(location = 2) in vec3 colour;\n"
    "uniform mat4 mvp;\n"
    "uniform vec3 light;\n"
    "uniform float lit, point_size;\n"
    "out vec3 shade;\n"
    "void main() {\n"
    "    float d = abs(dot(normalize(normal + vec3(1e-9)), light));\n"
    "    shade = mix(colour, colour * (0.3 + 0.7 * d), lit);\n"
    "    gl_PointSize = point_size;\n"
    "    gl_Position = mvp * vec4(position, 1.0);\n"
    "}\n";

static const char *vw__fragment_shader =
    "#version 330 core\n"
    "in vec3 shade;\n"
    "out vec4 colour;\n"
    "void main() { colour = vec4(shade, 1.0); }\n";

static int vw__load(vw_gl_loader load, char *err)
{
#define VW_GL_LOAD(ret, name, params)                                                              \
    *(vw_gl_proc *)&gl.name = load("gl" #name);                                                    \
    if (!gl.name) return snprintf(err, 256, "OpenGL function gl%s not found", #name), -1;
    VW_GL_FUNCTIONS(VW_GL_LOAD)
#undef VW_GL_LOAD
    return 0;
}

static GLuint vw__shader(GLenum type, const char *text, char *err)
{
    GLuint s = gl.CreateShader(type);
    GLint ok = 0;
    gl.ShaderSource(s, 1, &text, NULL);
    gl.CompileShader(s);
    gl.GetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[200];
        gl.GetShaderInfoLog(s, sizeof log, NULL, log);
        snprintf(err, 256, "shader: %s", log);
        gl.DeleteShader(s);
        return 0;
    }
    return s;
}

static int vw__program_create(char *err)
{
    GLuint v = vw__shader(GL_VERTEX_SHADER, vw__vertex_shader, err), f;
    GLint ok = 0;
    if (!v) return -1;
    f = vw__shader(GL_FRAGMENT_SHADER, vw__fragment_shader, err);
    if (!f) return -1;
    vw__program = gl.CreateProgram();
    gl.AttachShader(vw__program, v);
    gl.AttachShader(vw__program, f);
    gl.LinkProgram(vw__program);
    gl.DeleteShader(v);
    gl.DeleteShader(f);
    gl.GetProgramiv(vw__program, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[200];
        gl.GetProgramInfoLog(vw__program, sizeof log, NULL, log);
        return snprintf(err, 256, "link: %s", log), -1;
    }
    vw__u_mvp = gl.GetUniformLocation(vw__program, "mvp");
    vw__u_light = gl.GetUniformLocation(vw__program, "light");
    vw__u_lit = gl.GetUniformLocation(vw__program, "lit");
    vw__u_point = gl.GetUniformLocation(vw__program, "point_size");
    return 0;
}

int vw_render_init(vw_gl_loader load, char *err)
{
    int k;
    if (vw__load(load, err) || vw__program_create(err)) return -1;
    gl.GenVertexArrays(1, &vw__vao);
    gl.BindVertexArray(vw__vao);
    gl.GenBuffers(1, &vw__vbo);
    gl.BindBuffer(GL_ARRAY_BUFFER, vw__vbo);
    for (k = 0; k < 3; k++) {
        gl.EnableVertexAttribArray((GLuint)k);
        gl.VertexAttribPointer((GLuint)k, 3, GL_FLOAT, 0, VW_VERTEX_FLOATS * sizeof(float),
                               (const void *)(3 * k * sizeof(float)));
    }
    gl.Enable(GL_DEPTH_TEST);
    gl.Enable(GL_PROGRAM_POINT_SIZE);
    gl.Enable(GL_POLYGON_OFFSET_FILL); /* lines drawn over their faces stay visible */
    gl.PolygonOffset(1, 1);
    return 0;
}

void vw_render_begin(int width, int height, int wireframe)
{
    gl.Viewport(0, 0, width, height);
    gl.ClearColor(0.93f, 0.94f, 0.96f, 1);
    gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    vw_render_wireframe(wireframe);
    gl.UseProgram(vw__program);
}

void vw_render_wireframe(int on) { gl.PolygonMode(GL_FRONT_AND_BACK, on ? GL_LINE : GL_FILL); }

void vw_render_batch(int primitive, const float *vertices, int count, const float mvp[16], const float light[3],
                     int lit, float point_size)
{
    static const GLenum modes[3] = {GL_TRIANGLES, GL_LINES, GL_POINTS};
    if (count <= 0) return;
    gl.UniformMatrix4fv(vw__u_mvp, 1, 0, mvp);
    gl.Uniform3fv(vw__u_light, 1, light);
    gl.Uniform1f(vw__u_lit, lit ? 1.0f : 0.0f);
    gl.Uniform1f(vw__u_point, point_size);
    gl.BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(float) * VW_VERTEX_FLOATS * (size_t)count), vertices,
                  GL_STREAM_DRAW);
    gl.DrawArrays(modes[primitive], 0, count);
}

void vw_render_read(int width, int height, unsigned char *rgb)
{
    size_t row = 3 * (size_t)width;
    unsigned char tmp[3 * 4096];
    int y;
    gl.Finish();
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.ReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rgb);
    for (y = 0; y < height / 2 && row <= sizeof tmp; y++) { /* GL's first row is the bottom one */
        memcpy(tmp, rgb + y * row, row);
        memcpy(rgb + y * row, rgb + (size_t)(height - 1 - y) * row, row);
        memcpy(rgb + (size_t)(height - 1 - y) * row, tmp, row);
    }
}

void vw_render_shutdown(void)
{
    if (!gl.DeleteProgram) return;
    gl.DeleteBuffers(1, &vw__vbo);
    gl.DeleteVertexArrays(1, &vw__vao);
    gl.DeleteProgram(vw__program);
}
