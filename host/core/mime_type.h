#pragma once
// The media type of a file by its name's extension: what the report embeds (data: URIs) and what
// `pneumo serve` answers its page's files with. Only the kinds pneumo writes or serves.
#include <cctype>
#include <string>

namespace pneumo {

inline const char* mime_type_of(const std::string& path) {
  const auto dot = path.find_last_of('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));   // .PNG as .png
  if (ext == "png") return "image/png";
  if (ext == "jpg" || ext == "jpeg") return "image/jpeg";
  if (ext == "html") return "text/html; charset=utf-8";
  if (ext == "js") return "text/javascript; charset=utf-8";
  if (ext == "css") return "text/css; charset=utf-8";
  if (ext == "svg") return "image/svg+xml";
  return "application/octet-stream";
}

}  // namespace pneumo
