#include "roles/scan_coverage.h"

#include <algorithm>
#include <cctype>

#include "anatomy/anatomical_axes.h"
#include "roles/structure_names.h"

namespace pneumo {

namespace {

std::string words(std::string name) {
  std::replace(name.begin(), name.end(), '_', ' ');
  return name;
}

/// Whether the name, lower-cased, starts with one of `starts` ("hip_left" starts with "hip"; the
/// gallbladder does not start with "bladder").
bool name_starts(const std::string& name, std::initializer_list<const char*> starts) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  for (const char* p : starts)
    if (n.rfind(p, 0) == 0) return true;
  return false;
}

std::string listed(const std::vector<std::string>& names, std::size_t at_most = 4) {
  std::string s;
  for (std::size_t i = 0; i < names.size() && i < at_most; ++i) s += (i ? ", " : "") + words(names[i]);
  if (names.size() > at_most) s += " and " + std::to_string(names.size() - at_most) + " more";
  return s;
}

}  // namespace

ScanCoverage scan_coverage(const RoleVolume& rv, const std::map<int, std::string>& names) {
  ScanCoverage c;
  const Geometry& g = rv.geometry;
  const SliceFrame f = slice_frame(g);
  const AnatomicalAxes ax = anatomical_axes(g);
  // The CT's own index ranges inside the padded grid.
  const int64_t lat0 = rv.pad.lo[f.lat], lat1 = f.n_lat - 1 - rv.pad.hi[f.lat];
  const int64_t ap0 = rv.pad.lo[f.ap], ap1 = f.n_ap - 1 - rv.pad.hi[f.ap];
  const int64_t si0 = rv.pad.lo[f.si], si1 = f.n_si - 1 - rv.pad.hi[f.si];
  const int64_t top = ax.sign[2] > 0 ? si1 : si0, bottom = ax.sign[2] > 0 ? si0 : si1;
  const int64_t front = f.ap_sign > 0 ? ap1 : ap0;   // the CT's own most anterior row

  std::vector<int64_t> area(std::size_t(f.n_si), 0);
  std::map<int, int64_t> in_top, in_bottom;
  std::vector<uint8_t> present(65536, 0);
  for (int64_t s = si0; s <= si1; ++s)
    for (int64_t a = ap0; a <= ap1; ++a)
      for (int64_t l = lat0; l <= lat1; ++l) {
        const int64_t v = f.index(l, a, s);
        const Role r = rv.role[std::size_t(v)];
        if (r == Role::Other) continue;
        ++area[std::size_t(s)];
        const uint16_t id = rv.label[std::size_t(v)];
        present[id] = 1;
        if (id != 0 && s == top) ++in_top[id];
        if (id != 0 && s == bottom) ++in_bottom[id];
        if (r == Role::Wall && (l == lat0 || l == lat1)) c.wall_cut_laterally = true;
        if (r == Role::Wall && a == front) c.wall_cut_anteriorly = true;
      }
  const int64_t widest = *std::max_element(area.begin(), area.end());
  const auto face = [&](int64_t s, const std::map<int, int64_t>& ids) {
    CutFace cf;
    cf.body_fraction = widest > 0 ? double(area[std::size_t(s)]) / double(widest) : 0.0;
    cf.cuts_body = cf.body_fraction >= kCutFraction;
    std::vector<std::pair<int64_t, std::string>> by_size;
    // Structures that hold at least kStructureShare of the slice's body: a rib's tip is not news.
    for (const auto& [id, n] : ids) {
      const auto name = names.find(id);
      if (name != names.end() && double(n) >= kStructureShare * double(area[std::size_t(s)]))
        by_size.push_back({n, name->second});
    }
    std::sort(by_size.begin(), by_size.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    for (const auto& [n, name] : by_size) cf.structures.push_back(name);
    return cf;
  };
  c.top = face(top, in_top);
  c.bottom = face(bottom, in_bottom);
  for (const auto& [id, name] : names) {
    if (id <= 0 || id > 65535 || !present[std::size_t(id)]) continue;
    if (name_starts(name, {"lung"})) c.lungs_in_view = true;
    if (name_starts(name, {"hip", "sacrum", "urinary_bladder", "bladder", "pubi", "pelvi", "femur"}))
      c.pelvis_in_view = true;
  }

  const auto cut_words = [](const CutFace& cf, const char* end) {
    if (!cf.cuts_body) return std::string("the body ends inside the scan at its ") + end;
    return std::string("the ") + end + " slice cuts the body" +
           (cf.structures.empty() ? std::string() : " through " + listed(cf.structures));
  };
  c.summary = "The scan covers " + std::string(c.lungs_in_view ? "the lung bases" : "from below the lungs") + " to " +
              (c.pelvis_in_view ? "the pelvis" : "above the pelvis") + "; " + cut_words(c.top, "top") + "; " +
              cut_words(c.bottom, "bottom") + ".";
  if (c.top.cuts_body)
    for (const std::string& s : c.top.structures)
      if (compartment_of(s) == Compartment::Peritoneal) {
        c.warnings.push_back("the top slice cuts the " + words(s) +
                             ": the cavity's roof (the diaphragm) lies above the scan; by default the cut face "
                             "slides in its plane (mesh.cut_faces), a diaphragm that neither rises nor gives "
                             "(material.thorax_compliance_l_per_cmh2o lets it move into the lungs): trust the "
                             "answer less near the top slice");
        break;
      }
  if (!names.empty() && !c.pelvis_in_view && c.bottom.cuts_body)
    c.warnings.push_back("no pelvis in view (no hip, sacrum or bladder): the scan stops above it, the lower "
                         "abdominal wall is cut at the bottom slice (by default held there as if it continued, "
                         "mesh.cut_faces), and the cavity below it is missing");
  if (c.wall_cut_laterally)
    c.warnings.push_back("the field of view cuts the abdominal wall at the side: the flank beyond it is missing "
                         "(by default held at the cut as if it continued, mesh.cut_faces)");
  if (c.wall_cut_anteriorly)
    c.warnings.push_back("the field of view cuts the abdominal wall in front: its skin is missing there");
  return c;
}

}  // namespace pneumo
