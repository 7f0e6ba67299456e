// Must NOT compile: solve and warp are siblings above mesh; neither declares the other.
#include "warp/warp.h"
