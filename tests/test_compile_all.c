/* Every header with its implementation in one translation unit (see compile_all.h). */
#include "compile_all.h"
