// docs/scene_reference.md, generated from the parameter table: one Markdown table per section and
// per kind of array item, in the table's order. The test suite checks that the committed file is
// this text, so the reference cannot fall behind the parser.
#include <sstream>
#include <stdexcept>
#include <string>

#include "scene/param_table.h"
#include "scene/scene.h"

namespace pneumo {
namespace {

using scene_detail::json;
using scene_detail::Kind;
using scene_detail::ParamInfo;
using scene_detail::TableDoc;

std::string cell(std::string s) {
  std::string out;
  for (char ch : s) {
    if (ch == '|') out += "\\|";
    else if (ch == '\n') out += ' ';
    else out += ch;
  }
  return out;
}

std::string code(const std::string& s) { return "`" + s + "`"; }

std::string default_text(const ParamInfo& p, const json& defaults) {
  if (p.c.required) return "*required*";
  if (p.kind == Kind::Section) return "";
  const json& v = defaults.at(p.key);
  if (v.is_null()) return "*unset*";
  return code(v.dump());
}

std::string allowed_text(const ParamInfo& p, const std::string& sub_title) {
  if (p.kind == Kind::Section) return "see " + code(sub_title);
  if (p.kind == Kind::ObjectArray) {
    const std::string items = p.allowed_text();
    return "items: see " + code(sub_title) + (items == "any" ? "" : "; " + items);
  }
  return p.allowed_text();
}

void write_table(std::ostringstream& md, const TableDoc& t, const std::string& title, const std::string& heading) {
  md << "## " << heading << "\n\n";
  md << "| key | type | default | allowed | unit | meaning |\n";
  md << "|---|---|---|---|---|---|\n";
  const json defaults = t.defaults();
  std::vector<std::pair<const ParamInfo*, std::string>> subs;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const ParamInfo& p = t.info(i);
    const std::string full = title.empty() ? p.key : title + "." + p.key;
    const std::string sub_title = p.kind == Kind::ObjectArray ? full + "[]" : full;
    if (p.sub) subs.emplace_back(&p, sub_title);
    md << "| " << code(p.key) << " | " << cell(p.type_text()) << " | " << cell(default_text(p, defaults)) << " | "
       << cell(allowed_text(p, sub_title)) << " | " << cell(p.unit) << " | " << cell(p.meaning) << " |\n";
  }
  md << "\n";
  for (const auto& [p, sub_title] : subs)
    write_table(md, *p->sub, sub_title,
                code(sub_title) + (p->kind == Kind::ObjectArray ? " (each item)" : ""));
}

}  // namespace

std::string scene_key_help(const std::string& dotted_path) {
  const TableDoc* table = &scene_detail::scene_table();
  std::size_t start = 0;
  while (true) {
    const std::size_t dot = dotted_path.find('.', start);
    const std::string key = dotted_path.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    const ParamInfo* p = table->find(key);
    if (!p) throw std::logic_error("scene_key_help: no scene key " + dotted_path);
    if (dot == std::string::npos) return p->meaning + " Allowed: " + p->allowed_text() + ".";
    if (!p->sub) throw std::logic_error("scene_key_help: " + key + " has no keys under it");
    table = p->sub;
    start = dot + 1;
  }
}

std::string scene_reference_markdown() {
  std::ostringstream md;
  md << "# Scene reference\n\n"
        "<!-- Generated from host/scene/scene_params.cpp by `pneumo scene --reference > "
        "docs/scene_reference.md`; do not edit by hand (a test compares this file with the generated "
        "text). -->\n\n"
        "A scene is a JSON file describing one case: inputs, how labels map to roles, mesh, material, "
        "load, solver, device, views and outputs.\n\n"
        "- Units are part of the key names (`_mm`, `_mmhg`, `_kpa`, `_ms`, `_deg`, `_kg_m3`, `_hu`, `_mm_s`). "
        "Points are world coordinates in millimetres, RAS+ (x right, y anterior, z superior), as in the "
        "CT's NIfTI header.\n"
        "- Every key may be left out and then takes its default, except those marked *required*. A key "
        "whose default is *unset* may also be given as `null`.\n"
        "- An unknown key, a wrong type or a value outside *allowed* is an error naming the file, the key's "
        "path (`render.cameras[1].fov_deg`, items counted from 0), the value and what is allowed; an unknown "
        "key gets the nearest known one suggested.\n"
        "- Relative paths resolve against the folder of the scene file; absolute ones are used as written.\n"
        "- `//` and `/* */` comments are allowed; a key may appear only once in an object.\n"
        "- Each run writes the scene it used, with every default filled in and paths resolved, beside its "
        "outputs; that file reads back as the same scene.\n"
        "- §n refers to a section of docs/method.md.\n\n";
  write_table(md, scene_detail::scene_table(), "", "Top level");
  md << "## The default scene\n\n"
        "Every key at its default, as a run writes it (keys in alphabetical order):\n\n"
        "```json\n"
     << default_scene().echo().dump(2) << "\n```\n";
  return md.str();
}

}  // namespace pneumo
