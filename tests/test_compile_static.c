/* Every header with its implementation in one translation unit, all functions static. */
#define TMASS_STATIC
#define HEML_STATIC
#define FRM_STATIC
#define TETMESH_STATIC
#include "compile_all.h"
