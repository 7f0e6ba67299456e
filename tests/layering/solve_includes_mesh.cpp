// Must compile: solve declares mesh (and, through it, core and domain). The control that shows the
// failing probes fail for the layering, not for a broken compile line.
#include "mesh/mesh.h"
#include "solve/solver.h"
