// Must NOT compile: the mesh layer does not declare render (CMakeLists.txt, pneumo_layer), so the
// render headers are not on its include path. tests/layering/CMakeLists.txt expects the error.
#include "render/camera_model.h"
