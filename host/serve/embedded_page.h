#pragma once
// The page `pneumo serve` answers with: host/serve/page/* (HTML, JavaScript, CSS) embedded into
// the library at build time (cmake/EmbedKernels.cmake), so the server needs no files at run time,
// no CDN and no build step of its own.
#include <string>
#include <vector>

#include "core/embedded_files.h"

namespace pneumo::serve {

using EmbeddedPageFile = EmbeddedFile;   // path relative to host/serve/page/, e.g. "index.html"

const std::vector<EmbeddedPageFile>& embedded_page();

}  // namespace pneumo::serve
