// The shape table of the synthetic abdomen: every structure in millimetres (RAS+: +x patient right, +y anterior,
// +z superior; body centred on x = 0, y = 0; z = 0 near the L2 body), painted in the priority order of
// build_anatomy(). Sizes are those of a normal adult; the sources are cited beside each structure.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "phantom/phantom_model.h"

namespace pneumo::phantom_detail {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

double smoothstep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

/// Piecewise-linear interpolation in a table of (x, y) sorted by x, clamped at the ends.
template <std::size_t N>
double interp(const std::array<std::array<double, 2>, N>& t, double x) {
  if (x <= t[0][0]) return t[0][1];
  for (std::size_t n = 1; n < N; ++n)
    if (x <= t[n][0]) {
      const double u = (x - t[n - 1][0]) / (t[n][0] - t[n - 1][0]);
      return t[n - 1][1] + u * (t[n][1] - t[n - 1][1]);
    }
  return t[N - 1][1];
}

/// Catmull–Rom through (x, y) knots sorted by x, clamped at the ends.
template <std::size_t N>
double catmull_rom(const std::array<std::array<double, 2>, N>& k, double x) {
  if (x <= k[0][0]) return k[0][1];
  if (x >= k[N - 1][0]) return k[N - 1][1];
  std::size_t n = 1;
  while (x > k[n][0]) ++n;
  const std::size_t i1 = n - 1, i2 = n;
  const std::size_t i0 = i1 > 0 ? i1 - 1 : i1, i3 = i2 + 1 < N ? i2 + 1 : i2;
  const double t = (x - k[i1][0]) / (k[i2][0] - k[i1][0]);
  const double p0 = k[i0][1], p1 = k[i1][1], p2 = k[i2][1], p3 = k[i3][1];
  return 0.5 * ((2 * p1) + (-p0 + p2) * t + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t * t + (-p0 + 3 * p1 - 3 * p2 + p3) * t * t * t);
}

uint64_t mix(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}
/// A fixed pseudo-random number in [0, 1) for construction-time jitter (not std::random: distributions differ
/// between standard libraries, and the phantom must be the same everywhere).
double jitter(uint64_t key) { return static_cast<double>(mix(key) >> 11) * (1.0 / 9007199254740992.0); }

// ---- the vertebral column -------------------------------------------------------------------------------------------
// Body heights ≈ 25–28 mm (lumbar) and 19–23 mm (lower thoracic), discs ≈ 10 mm (lumbar) and 5–7 mm (thoracic);
// lumbar bodies ≈ 45–50 mm wide × 33–36 mm deep (Panjabi et al., Spine 1992; Zhou et al., Eur Spine J 2000).
struct Level {
  const char* name;
  uint8_t id;
  double z_lo_mm, z_hi_mm;        // body end plates
  double semi_x_mm, semi_y_mm;    // body half width / half depth
  double transverse_mm;           // transverse process length from the canal edge
  bool lumbar;
};
constexpr Level kLevels[] = {
    {"L5", label::kVertebraL5, -140, -112, 25.0, 18.0, 24, true},
    {"L4", label::kVertebraL4, -101, -73, 25.0, 18.0, 28, true},
    {"L3", label::kVertebraL3, -62, -35, 24.0, 17.5, 32, true},   // L3: the longest transverse processes
    {"L2", label::kVertebraL2, -25, 1, 23.0, 17.0, 27, true},
    {"L1", label::kVertebraL1, 10, 35, 22.0, 16.5, 22, true},
    {"T12", label::kVertebraT12, 42, 65, 20.0, 16.0, 18, false},
    {"T11", label::kVertebraT11, 71, 93, 18.5, 15.5, 18, false},
    {"T10", label::kVertebraT10, 98, 119, 17.0, 15.0, 20, false},
    {"T9", label::kVertebraT9, 124, 144, 16.0, 14.5, 20, false},
    {"T8", label::kVertebraT8, 149, 168, 15.5, 14.0, 20, false},
    {"T7", label::kVertebraT7, 172, 191, 15.0, 14.0, 20, false},
};
constexpr int kLevelCount = sizeof(kLevels) / sizeof(kLevels[0]);
constexpr double kPromontoryZ = -150;   // top of S1 = bottom of the L5/S1 disc: the pelvic brim
constexpr double kPosteriorFatBoundaryY = -110 + 2 + 14;   // midline back: skin + subcutaneous fat

/// Vertebral body half-axes at height z (interpolated between level mid-heights).
V2 body_semi_at(double z) {
  if (z <= 0.5 * (kLevels[0].z_lo_mm + kLevels[0].z_hi_mm)) return V2(kLevels[0].semi_x_mm, kLevels[0].semi_y_mm);
  for (int n = 1; n < kLevelCount; ++n) {
    const double m0 = 0.5 * (kLevels[n - 1].z_lo_mm + kLevels[n - 1].z_hi_mm);
    const double m1 = 0.5 * (kLevels[n].z_lo_mm + kLevels[n].z_hi_mm);
    if (z <= m1) {
      const double u = (z - m0) / (m1 - m0);
      return V2(kLevels[n - 1].semi_x_mm + u * (kLevels[n].semi_x_mm - kLevels[n - 1].semi_x_mm),
                kLevels[n - 1].semi_y_mm + u * (kLevels[n].semi_y_mm - kLevels[n - 1].semi_y_mm));
    }
  }
  return V2(kLevels[kLevelCount - 1].semi_x_mm, kLevels[kLevelCount - 1].semi_y_mm);
}

/// Spinal canal half-axes: lumbar ≈ 22 × 17 mm, lower thoracic ≈ 17 × 16 mm.
V2 canal_semi_at(double z) {
  const double u = smoothstep(20, 70, z);
  return V2(11.0 - 2.5 * u, 8.5 - 0.5 * u);
}
double canal_centre_y(double z) { return spine_y_mm(z) - body_semi_at(z).y() - canal_semi_at(z).y() - 1.0; }

/// The anterior surface of the vertebral bodies (where the aorta and IVC lie).
double prevertebral_y(double z) { return spine_y_mm(z) + body_semi_at(z).y(); }

void paint_ellipse(const PaintContext& ctx, Slice& s, ZoneMask zones, V2 c, V2 semi, uint8_t lab, const Fill& fill,
                   double cap_depth_mm) {
  const PlaneGrid& g = ctx.grid;
  const Paint p{lab, fill, zones};
  const double min_semi = semi.minCoeff();
  for (int j = g.j_first(c.y() - semi.y()); j <= g.j_last(c.y() + semi.y()); ++j) {
    const double v = (g.y(j) - c.y()) / semi.y();
    for (int i = g.i_first(c.x() - semi.x()); i <= g.i_last(c.x() + semi.x()); ++i) {
      const double u = (g.x(i) - c.x()) / semi.x();
      const double f = u * u + v * v;
      if (f > 1) continue;
      const int64_t n = int64_t(j) * g.nx + i;
      if (!paint_allowed(p, ctx, s, n)) continue;
      FillSample fs{std::min((1 - std::sqrt(f)) * min_semi, cap_depth_mm), g.x(i), g.y(j), s.z_mm};
      s.label[n] = lab;
      s.hu[n] = fill_hu(fill, fs, g.min_spacing_mm);
    }
  }
}

/// A flat 2-D capsule (segment a–b with radius r) in this slice.
void paint_capsule_2d(const PaintContext& ctx, Slice& s, ZoneMask zones, V2 a, V2 b, double r, uint8_t lab,
                      const Fill& fill) {
  const PlaneGrid& g = ctx.grid;
  const Paint p{lab, fill, zones};
  const V2 d = b - a;
  const double len2 = std::max(d.squaredNorm(), 1e-12);
  for (int j = g.j_first(std::min(a.y(), b.y()) - r); j <= g.j_last(std::max(a.y(), b.y()) + r); ++j) {
    for (int i = g.i_first(std::min(a.x(), b.x()) - r); i <= g.i_last(std::max(a.x(), b.x()) + r); ++i) {
      const V2 q(g.x(i), g.y(j));
      const double t = std::clamp((q - a).dot(d) / len2, 0.0, 1.0);
      const double dist = (q - a - t * d).norm();
      if (dist > r) continue;
      const int64_t n = int64_t(j) * g.nx + i;
      if (!paint_allowed(p, ctx, s, n)) continue;
      FillSample fs{r - dist, q.x(), q.y(), s.z_mm};
      s.label[n] = lab;
      s.hu[n] = fill_hu(fill, fs, g.min_spacing_mm);
    }
  }
}

const Fill kVertebralBone = Fill::bone(hu::kCorticalBone, hu::kCancellousBone, 1.5);
// Posterior elements are thin plates of mostly compact bone: a cortex twice as thick relative to their size.
const Fill kPosteriorElementBone = Fill::bone(hu::kCorticalBone, hu::kCancellousBone + 150, 2.0);

/// The column: sacrum, discs, bodies (cortical rim around cancellous bone), arches with spinous and transverse
/// processes, and the canal contents.
void paint_spine(const PaintContext& ctx, Slice& s) {
  const double z = s.z_mm;
  const ZoneMask zones = kInMuscleOrCavity;
  const double ys = spine_y_mm(z);
  if (z > kLevels[kLevelCount - 1].z_hi_mm + 10) return;

  if (z < kPromontoryZ) {
    // Upper sacrum: S1 body with its alae (≈ 100–110 mm across at S1), tilting backwards below the promontory.
    const double below = kPromontoryZ - z;
    const V2 semi(52.0 - 0.25 * below, 21.0);
    const PlaneGrid& g = ctx.grid;
    const Paint p{label::kSacrum, kVertebralBone, zones};
    for (int j = g.j_first(ys - semi.y()); j <= g.j_last(ys + semi.y()); ++j) {
      const double v = (g.y(j) - ys) / semi.y();
      for (int i = g.i_first(-semi.x()); i <= g.i_last(semi.x()); ++i) {
        const double u = g.x(i) / semi.x();
        const double f = u * u * u * u + v * v * v * v;
        if (f > 1) continue;
        const int64_t n = int64_t(j) * g.nx + i;
        if (!paint_allowed(p, ctx, s, n)) continue;
        FillSample fs{(1 - std::sqrt(std::sqrt(f))) * semi.minCoeff(), g.x(i), g.y(j), z};
        s.label[n] = label::kSacrum;
        s.hu[n] = fill_hu(kVertebralBone, fs, g.min_spacing_mm);
      }
    }
    // Median sacral crest.
    paint_capsule_2d(ctx, s, zones, V2(0, ys - semi.y() + 2), V2(0, ys - semi.y() - 12), 4.0, label::kSacrum,
                     kPosteriorElementBone);
    // Sacral canal (nerve roots in CSF): continues the canal label.
    paint_ellipse(ctx, s, zones, V2(0, ys - 9), V2(10, 5), label::kSpinalCord, Fill::solid(hu::kCsf), 1e9);
    return;
  }

  // Body or disc at this height.
  bool in_body = false;
  for (int n = 0; n < kLevelCount; ++n) {
    const Level& L = kLevels[n];
    if (z >= L.z_lo_mm && z <= L.z_hi_mm) {
      const double cap = std::min(z - L.z_lo_mm, L.z_hi_mm - z);
      paint_ellipse(ctx, s, zones, V2(0, ys), V2(L.semi_x_mm, L.semi_y_mm), L.id, kVertebralBone, cap);
      in_body = true;
      break;
    }
  }
  if (!in_body) {
    paint_ellipse(ctx, s, zones, V2(0, ys), body_semi_at(z) - V2(0.5, 0.5), label::kIntervertebralDisc,
                  Fill::solid(hu::kDisc), 1e9);
  }

  // Posterior elements of the levels whose arch spans this height. Arch: pedicles from the upper body, laminae
  // reaching down over the disc below; interlaminar gaps between levels.
  const V2 canal = canal_semi_at(z);
  const double yc = canal_centre_y(z);
  for (int n = 0; n < kLevelCount; ++n) {
    const Level& L = kLevels[n];
    const double h = L.z_hi_mm - L.z_lo_mm;
    const double arch_lo = L.z_lo_mm - 0.02 * h, arch_hi = L.z_hi_mm - 0.18 * h;
    if (z < arch_lo - 25 || z > arch_hi + 5) continue;   // spinous processes hang below the arch
    const bool in_arch = z >= arch_lo && z <= arch_hi;
    const double arch_mid = 0.5 * (arch_lo + arch_hi);
    if (in_arch) {
      // Ring around the canal: pedicles and laminae, ≈ 6–7 mm of bone.
      const PlaneGrid& g = ctx.grid;
      const V2 outer = canal + V2(7.0, 6.0);
      const Paint p{L.id, kPosteriorElementBone, zones};
      for (int j = g.j_first(yc - outer.y()); j <= g.j_last(yc + outer.y()); ++j) {
        const double vo = (g.y(j) - yc) / outer.y(), vi = (g.y(j) - yc) / canal.y();
        for (int i = g.i_first(-outer.x()); i <= g.i_last(outer.x()); ++i) {
          const double uo = g.x(i) / outer.x(), ui = g.x(i) / canal.x();
          const double fo = uo * uo + vo * vo, fi = ui * ui + vi * vi;
          if (fo > 1 || fi < 1) continue;
          const int64_t q = int64_t(j) * g.nx + i;
          if (!paint_allowed(p, ctx, s, q)) continue;
          FillSample fs{std::min(1 - std::sqrt(fo), std::sqrt(fi) - 1) * 6.0, g.x(i), g.y(j), z};
          s.label[q] = L.id;
          s.hu[q] = fill_hu(kPosteriorElementBone, fs, g.min_spacing_mm);
        }
      }
      // Transverse processes: lateral in the lumbar spine, posterolateral (to the rib tubercles) in the thorax.
      if (std::abs(z - arch_mid) < 6.0) {
        for (const double sx : {-1.0, 1.0}) {
          const V2 a(sx * (canal.x() + 3), yc + 2);
          const V2 b = L.lumbar ? V2(sx * (canal.x() + 3 + L.transverse_mm), yc)
                                : V2(sx * (canal.x() + 3 + L.transverse_mm), yc - 10);
          paint_capsule_2d(ctx, s, zones, a, b, L.lumbar ? 4.5 : 5.0, L.id, kPosteriorElementBone);
        }
      }
    }
    // Spinous process: a midline plate sloping caudally (gently in the lumbar spine, steeply in the thorax).
    const double half_w = L.lumbar ? 4.0 : 3.0, half_h = L.lumbar ? 10.0 : 6.0, len = L.lumbar ? 30.0 : 18.0;
    const double tilt = L.lumbar ? 0.2 : 0.8;
    const double y0 = yc - canal.y() - 4.0;
    const double zc = arch_mid - 0.1 * h;
    const PlaneGrid& g = ctx.grid;
    const Paint p{L.id, kPosteriorElementBone, zones};
    for (int j = g.j_first(y0 - len); j <= g.j_last(y0); ++j) {
      const double back = y0 - g.y(j);
      const double zmid = zc - tilt * back;
      if (std::abs(z - zmid) > half_h) continue;
      for (int i = g.i_first(-half_w); i <= g.i_last(half_w); ++i) {
        const int64_t q = int64_t(j) * g.nx + i;
        if (!paint_allowed(p, ctx, s, q)) continue;
        const double depth = std::min({half_w - std::abs(g.x(i)), half_h - std::abs(z - zmid), len - back});
        FillSample fs{depth, g.x(i), g.y(j), z};
        s.label[q] = L.id;
        s.hu[q] = fill_hu(kPosteriorElementBone, fs, g.min_spacing_mm);
      }
    }
  }
  // Canal contents: cord and CSF (the cauda equina below L1–L2), one label.
  paint_ellipse(ctx, s, zones, V2(0, yc), canal, label::kSpinalCord, Fill::solid(hu::kCsf), 1e9);
}

// ---- diaphragm, lung bases, heart ----------------------------------------------------------------------------------
/// Height of the diaphragm's upper surface above (x, y): two domes (right higher, ≈ T9–T10 at end inspiration)
/// over a central tendon where the heart rests, falling steeply into the posterior costophrenic recess (≈ L1) and
/// less steeply anteriorly towards the xiphoid.
double diaphragm_z(double x, double y) {
  const double dome_r = 145 - 0.010 * (x - 60) * (x - 60);
  const double dome_l = 133 - 0.010 * (x + 60) * (x + 60);
  const double central = 118 - 0.002 * x * x;
  const double dy = y + 5;
  const double fall = dy < 0 ? 0.014 * dy * dy : 0.0025 * dy * dy;
  return std::max({dome_r, dome_l, central}) - fall;
}

struct ThoraxCache {
  std::vector<float> z_top, z_bottom;   // diaphragm upper surface and lower surface per column
  float z_min = 1e9f;
};

// ---- iliac wings -----------------------------------------------------------------------------------------------------
struct WingCache {
  // Per column and side: signed distance to the wing's mid-surface curve at the crest (positive towards the iliac
  // fossa, i.e. medially/anteriorly) and the arc parameter s ∈ [0, 1] from the sacro-iliac joint to the ASIS.
  std::vector<float> sd[2], s[2];
};

/// Crest height along the wing: highest laterally (≈ L4, the intercristal line), lower at the posterior superior
/// iliac spine and at the anterior superior iliac spine.
double wing_crest_z(double s) {
  const double post = std::max(0.0, (0.35 - s) / 0.35), ant = std::max(0.0, (s - 0.55) / 0.45);
  return -88 - 60 * post * post - 35 * ant * ant;
}
constexpr double kWingTopZ = -88;

// ---- ribs ----------------------------------------------------------------------------------------------------------
/// One rib: attached at its vertebra, running round the body inside the wall and descending forwards; ribs 7–10
/// continue as costal cartilage rising towards the sternum (the costal margin). Angles ψ are measured round the body
/// from the posterior midline (0°) through the flank (90°) to the anterior midline (180°). The costal margin is lowest
/// at the 10th costal cartilage (subcostal plane ≈ L2–L3); the floating ribs 11 and 12 end in the flank. A rib's
/// cross-section is ≈ 10 × 6 mm (drawn as a 9–10 mm circle).
struct RibSpec {
  int n;
  double z_head_mm;                     // height at the rib angle
  double psi_bone_end_deg, z_bone_end_mm;
  double psi_cartilage_end_deg, z_cartilage_end_mm;   // psi ≤ bone end: no cartilage (floating ribs)
  double radius_mm;
};
constexpr RibSpec kRibs[] = {
    {7, 183, 140, 125, 172, 160, 5.0},
    {8, 158, 132, 90, 160, 128, 5.0},
    {9, 133, 123, 52, 148, 95, 5.0},
    {10, 108, 113, 15, 135, 60, 5.0},
    {11, 82, 95, 0, 0, 0, 4.5},
    {12, 56, 62, 18, 0, 0, 4.0},
};

V2 inward_normal(const TorsoModel& t, double theta) {
  const V2 tangent = t.outline(theta + 1e-4) - t.outline(theta - 1e-4);
  V2 n(-tangent.y(), tangent.x());
  n.normalize();
  if (n.dot(t.outline(theta)) > 0) n = -n;
  return n;
}

/// A point inside the wall at angle ψ on side sx (+1 right, −1 left), `inset` mm deeper than the subcutaneous fat.
V3 wall_point(const TorsoModel& t, double sx, double psi_deg, double inset_mm, double z) {
  const double theta = sx > 0 ? (psi_deg - 90) * kDeg : (270 - psi_deg) * kDeg;
  const V2 b = t.outline(theta);
  const V2 p = b + inward_normal(t, theta) * (t.skin_nominal_mm + t.subcut_fat_mm(theta) + inset_mm);
  return V3(p.x(), p.y(), z);
}

std::vector<TubeNode> rib_nodes(const TorsoModel& t, const RibSpec& r, double sx, bool cartilage) {
  constexpr double kAngle = 38;   // the rib angle, lateral to the erector spinae
  std::vector<TubeNode> nodes;
  if (!cartilage) {
    // Neck: from the transverse process of its vertebra to the angle.
    const double zc = r.z_head_mm + 3;
    const V2 canal = canal_semi_at(zc);
    nodes.push_back({V3(sx * (canal.x() + 20), canal_centre_y(zc) - 9, zc), r.radius_mm});
    for (double psi = kAngle; psi < r.psi_bone_end_deg + 1e-9; psi += 5) {
      const double u = (psi - kAngle) / (r.psi_bone_end_deg - kAngle);
      const double z = r.z_head_mm - (r.z_head_mm - r.z_bone_end_mm) * u;
      const double inset = 7 + 14 * std::max(0.0, (55 - psi) / 17);
      nodes.push_back({wall_point(t, sx, psi, inset, z), r.radius_mm});
    }
  } else {
    for (double psi = r.psi_bone_end_deg; psi < r.psi_cartilage_end_deg + 1e-9; psi += 4) {
      const double u = (psi - r.psi_bone_end_deg) / (r.psi_cartilage_end_deg - r.psi_bone_end_deg);
      const double z = r.z_bone_end_mm + (r.z_cartilage_end_mm - r.z_bone_end_mm) * u;
      nodes.push_back({wall_point(t, sx, psi, 6, z), r.radius_mm});
    }
  }
  return nodes;
}

// ---- small bowel -----------------------------------------------------------------------------------------------------
/// The jejunum and ileum as one tube (≈ 22 mm calibre, normal < 25–30 mm) folded into serpentine loops, from the
/// duodeno-jejunal flexure (left of L2) to the ileocaecal valve (right iliac fossa): jejunal loops in the left
/// flank in front of the kidney and psoas, then an anterior and a posterior layer filling the central and lower
/// abdomen. Some anterior loops hold a little gas (supine: gas rises anteriorly).
std::vector<TubeNode> small_bowel_nodes() {
  constexpr double kRadius = 11;
  constexpr double kRowStep = 28;   // loops 28 mm apart: ≈ 6 mm of mesenteric fat between them
  struct Layer {
    const char* where;
    double y_mm, z_first_mm, z_last_mm;   // rows from z_first to z_last (either direction)
    double x_lo_upper_mm, x_hi_upper_mm;  // row extent above z = −70 (clear of the liver, duodenum, colon)
    double x_lo_lower_mm, x_hi_lower_mm;  // and below
    bool end_on_right;                    // direction of the last row (so the ileum ends at the caecum)
    bool gas;                             // some loops of this layer hold gas
  };
  const Layer layers[] = {
      {"left flank, jejunum", 0, -12, -138, -94, -52, -94, -52, false, false},
      {"anterior", 57, -180, -40, -78, 40, -86, 70, false, true},
      {"posterior, ileum", 30, -25, -180, -78, 40, -86, 70, true, false},
  };
  std::vector<TubeNode> nodes;
  nodes.push_back({V3(-38, 28, -5), kRadius});   // duodeno-jejunal flexure
  int row_id = 0;
  for (const Layer& L : layers) {
    std::vector<double> zs;
    const double step = L.z_last_mm < L.z_first_mm ? -kRowStep : kRowStep;
    for (double z = L.z_first_mm; (z - L.z_last_mm) * step <= 1e-9; z += step) zs.push_back(z);
    // Alternate directions so that the last row runs the way the layer is meant to end.
    bool left_to_right = (zs.size() % 2 == 1) == L.end_on_right;
    // Waves in z share one phase per layer so neighbouring rows stay parallel and never fuse, while each row still
    // crosses the axial planes often (round and oval sections); waves in y vary per row.
    const double ph_z = 2 * kPi * jitter(2000 + static_cast<uint64_t>(L.y_mm));
    for (std::size_t r = 0; r < zs.size(); ++r, ++row_id) {
      const double z_row = zs[r];
      const double x_lo = z_row > -70 ? L.x_lo_upper_mm : L.x_lo_lower_mm;
      const double x_hi = z_row > -70 ? L.x_hi_upper_mm : L.x_hi_lower_mm;
      const double ph_y = 2 * kPi * jitter(1000 + row_id);
      const bool gas = L.gas && row_id % 3 == 1;
      const int steps = static_cast<int>(std::ceil((x_hi - x_lo) / 6.0));
      for (int q = 0; q <= steps; ++q) {
        const double u = static_cast<double>(q) / steps;
        const double x = left_to_right ? x_lo + u * (x_hi - x_lo) : x_hi - u * (x_hi - x_lo);
        const double y = L.y_mm + 7 * std::sin(0.07 * x + ph_y);
        const double z = z_row + 9 * std::sin(0.10 * x + ph_z);
        nodes.push_back({V3(x, y, z), kRadius, gas});
      }
      // U-turn to the next row, bulging outwards.
      if (r + 1 < zs.size()) {
        const double x_end = left_to_right ? x_hi : x_lo;
        nodes.push_back({V3(x_end + (left_to_right ? 10 : -10), L.y_mm, 0.5 * (z_row + zs[r + 1])), kRadius});
      }
      left_to_right = !left_to_right;
    }
  }
  nodes.push_back({V3(66, 18, -140), kRadius});   // terminal ileum into the caecum
  return nodes;
}

// ---- helpers for the vessels following the spine -----------------------------------------------------------------
std::vector<TubeNode> aorta_nodes() {
  // Abdominal aorta ≈ 20–22 mm wide tapering to ≈ 18 mm at the bifurcation (L4); descending thoracic ≈ 24 mm;
  // left-anterior of the vertebral bodies (normal diameters: Wanhainen et al., ESVS guidelines 2019).
  std::vector<TubeNode> n;
  for (double z = 200; z >= -85 - 1e-9; z -= 10) {
    const double r = z > 100 ? 12.0 : (z > 40 ? 11.0 + (z - 40) / 60.0 : 9.5 + 1.5 * (z + 85) / 125.0);
    const double x = -14 - 8 * smoothstep(60, 140, z);
    n.push_back({V3(x, prevertebral_y(z) + 2 + r, z), r});
  }
  return n;
}

std::vector<TubeNode> ivc_nodes() {
  // IVC ≈ 20–25 mm, right-anterior of the spine, moving forwards into the liver's bare area before piercing the
  // diaphragm at T8–T9.
  std::vector<TubeNode> n;
  for (double z = -115; z <= 132 + 1e-9; z += 10) {
    const double r = z < -85 ? 10.0 : 11.5;
    const double x = z < -85 ? 12 + 8 * (z + 115) / 30.0 : 22 + 4 * smoothstep(0, 80, z);
    const double forward = 14 * smoothstep(40, 110, z);
    n.push_back({V3(x, prevertebral_y(z) + 2 + r + forward, z), r});
  }
  return n;
}

Paint paint_of(uint8_t lab, Fill fill, ZoneMask zones = kInCavity, int only_over = -1) {
  Paint p;
  p.label = lab;
  p.fill = fill;
  p.zones = zones;
  p.only_over = only_over;
  return p;
}

// Bowel fills.
const Fill kSmallBowelFill = Fill::hollow(hu::kBowelWall, hu::kBowelFluid, 2.5);
const Fill kColonFill = Fill::hollow(hu::kBowelWall, hu::kStool, 2.5, Content::Stool);
const Fill kBloodFill = Fill::solid(hu::kBlood);
}  // namespace

double spine_y_mm(double z_mm) {
  // Centre of the vertebral bodies: lumbar lordosis (most anterior at L3–L4), thoracic kyphosis above, and the
  // sacrum tilting backwards below the promontory (sacral slope ≈ 40°).
  static const std::array<std::array<double, 2>, 8> knots{{{-200, -82},
                                                           {-150, -45},
                                                           {-110, -30},
                                                           {-60, -21},
                                                           {-10, -24},
                                                           {40, -31},
                                                           {100, -38},
                                                           {200, -46}}};
  return catmull_rom(knots, z_mm);
}

Anatomy build_anatomy() {
  Anatomy a;
  const TorsoModel& torso = a.torso;
  auto add = [&](std::unique_ptr<Shape> s) { a.shapes.push_back(std::move(s)); };

  // ---- CT table: curved carbon-fibre top (≈ 40 mm, foam core) with a 25 mm mattress, touching the back --------
  add(make_custom([](const PaintContext& ctx, Slice& s) {
    const PlaneGrid& g = ctx.grid;
    const Fill slab = Fill::bone(hu::kTableShell, hu::kTableFoam, 2.5);   // shells around a foam core
    for (int i = 0; i < g.nx; ++i) {
      const double x = g.x(i);
      const double y_top = -110.5 + x * x / (2 * 600.0);   // 600 mm radius of curvature
      const double pad_lo = y_top - 25, slab_lo = pad_lo - 40;
      for (int j = g.j_first(slab_lo); j <= g.j_last(y_top); ++j) {
        const int64_t n = int64_t(j) * g.nx + i;
        if (ctx.torso.zone[n] != kZoneOut) continue;
        const double y = g.y(j);
        if (y >= pad_lo) {
          s.label[n] = label::kCtTablePad;
          s.hu[n] = hu::kPadFoam;
        } else {
          FillSample fs{std::min(pad_lo - y, y - slab_lo), x, y, s.z_mm};
          s.label[n] = label::kCtTable;
          s.hu[n] = fill_hu(slab, fs, g.min_spacing_mm);
        }
      }
    }
  }));

  // ---- bowel (lowest priority inside the cavity: solid organs and vessels override where they meet) ------------
  {
    TubeSpec sb{"small bowel", small_bowel_nodes(), paint_of(label::kSmallBowel, kSmallBowelFill)};
    sb.gas_cap_level = 0.3f;
    add(make_tube(std::move(sb)));
  }
  // Duodenum: bulb (with a little gas), descending, horizontal (between aorta and SMA) and ascending parts.
  {
    TubeSpec d{"duodenum",
               {{V3(24, 40, 37), 11, true},
                {V3(40, 30, 40), 13},
                {V3(52, 12, 28), 13},
                {V3(55, -2, 0), 13},
                {V3(50, 0, -28), 12},
                {V3(25, 28, -42), 12},
                {V3(-8, 34, -42), 11},
                {V3(-30, 30, -25), 11},
                {V3(-38, 28, -5), 11}},
               paint_of(label::kDuodenum, kSmallBowelFill)};
    d.gas_cap_level = 0.4f;
    add(make_tube(std::move(d)));
  }
  // Colon: caecum and ascending colon (right), transverse colon hanging anteriorly (gas), splenic flexure high on
  // the left, descending colon, sigmoid. Calibre ≈ 50–60 mm caecum, 40–45 mm elsewhere (normal < 60 / < 50 mm).
  {
    TubeSpec c{"colon",
               {{V3(88, 15, -135), 30},
                {V3(98, 0, -95), 27},
                {V3(102, -5, -50), 26},
                {V3(100, 0, -10), 25, true},
                {V3(85, 30, 5), 24, true},
                {V3(45, 58, -10), 22, true},
                {V3(0, 60, -18), 21, true},
                {V3(-45, 57, 0), 21, true},
                {V3(-80, 35, 40), 21, true},
                {V3(-100, 5, 62), 21},
                {V3(-110, -15, 30), 19},
                {V3(-112, -20, -30), 18},
                {V3(-108, -18, -90), 18},
                {V3(-95, -8, -135), 17, true},
                {V3(-60, 10, -165), 17},
                {V3(-20, 15, -182), 17},
                {V3(5, -20, -205), 16}},
               paint_of(label::kColon, kColonFill)};
    c.gas_cap_level = 0.0f;
    add(make_tube(std::move(c)));
  }
  // Stomach: fundus under the left dome, body, antrum, pylorus; wall ≈ 4 mm; supine air-fluid level: gas in the
  // anterior (upper) part, fluid posteriorly. Volume ≈ 0.5 L (moderately filled).
  add(make_tube({"stomach",
                 {{V3(-52, -18, 115), 34},
                  {V3(-62, 10, 90), 36},
                  {V3(-55, 45, 62), 30},
                  {V3(-20, 58, 44), 22},
                  {V3(8, 50, 36), 16},
                  {V3(24, 40, 37), 11}},
                 paint_of(label::kStomach, Fill::hollow(hu::kBowelWall, hu::kGastricFluid, 4.0, Content::GasAbovePlane, 42))}));
  // Pancreas: head in the duodenal C-loop, neck anterior to the portal confluence, body over the aorta, tail to the
  // splenic hilum; ≈ 70–90 ml (ICRP 89: 140 g in men, 120 g in women).
  add(make_tube({"pancreas",
                 {{V3(32, 30, -4), 15}, {V3(6, 40, 12), 11}, {V3(-28, 35, 28), 12}, {V3(-62, 12, 42), 10}, {V3(-82, -10, 52), 8}},
                 paint_of(label::kPancreas, Fill::solid(hu::kPancreas))}));

  // ---- liver: right lobe (most of its ≈ 1.5 L), left lobe across the midline anterior to the stomach, and the
  // medial segment/caudate joining them; its dome is cut by the diaphragm (painted later). ICRP 89: 1800 g (men),
  // 1400 g (women); density ≈ 1.06 g/ml → 1.3–1.7 L. Craniocaudal span of the right lobe ≈ 15 cm (normal < 16 cm).
  add(make_ellipsoid({"liver, right lobe", V3(72, 0, 75), V3(62, 82, 78), V3::UnitX(), V3::UnitY(),
                      paint_of(label::kLiver, Fill::solid(hu::kLiver))}));
  add(make_ellipsoid({"liver, medial segment and caudate", V3(22, 20, 98), V3(45, 42, 42), V3::UnitX(), V3::UnitY(),
                      paint_of(label::kLiver, Fill::solid(hu::kLiver))}));
  add(make_ellipsoid({"liver, left lobe", V3(-18, 44, 104), V3(62, 30, 30), V3(1, 0, -0.25), V3::UnitY(),
                      paint_of(label::kLiver, Fill::solid(hu::kLiver))}));
  // Hepatic veins inside the liver (unenhanced blood, slightly darker than parenchyma): liver label, vessel HU.
  for (const V3& tip : {V3(98, -15, 100), V3(45, 35, 108), V3(-12, 42, 112)}) {
    const V3 root(25, prevertebral_y(125) + 16 + 12, 125);
    add(make_tube({"hepatic vein", {{root, 6}, {0.5 * (root + tip), 5}, {tip, 2.5}},
                   paint_of(label::kLiver, kBloodFill, kInCavity, label::kLiver)}));
  }
  // Portal vein from the confluence behind the pancreatic neck to the porta hepatis, with right and left branches;
  // splenic vein along the back of the pancreas. (TotalSegmentator: portal_vein_and_splenic_vein.)
  add(make_tube({"portal vein",
                 {{V3(8, 24, 20), 7}, {V3(28, 22, 52), 7.5}, {V3(55, 12, 70), 5.5}, {V3(85, 5, 84), 4}},
                 paint_of(label::kPortalVein, kBloodFill)}));
  add(make_tube({"left portal vein", {{V3(28, 22, 52), 5}, {V3(5, 35, 80), 4.5}, {V3(-25, 45, 95), 3.5}},
                 paint_of(label::kPortalVein, kBloodFill)}));
  add(make_tube({"splenic vein",
                 {{V3(8, 24, 20), 5}, {V3(-30, 20, 30), 5}, {V3(-68, -2, 48), 4.5}, {V3(-86, -24, 60), 4}},
                 paint_of(label::kPortalVein, kBloodFill)}));
  // Gallbladder under the liver: neck, body, fundus at the inferior liver edge; ≈ 30–50 ml fasting.
  add(make_tube({"gallbladder", {{V3(45, 28, 55), 7}, {V3(56, 44, 33), 15}, {V3(60, 52, 20), 16}},
                 paint_of(label::kGallbladder, Fill::hollow(hu::kBowelWall, hu::kBile, 2.0))}));

  // ---- spleen: left upper quadrant, posterolateral, long axis along the 10th rib; ≈ 12 × 7 × 4 cm, 150–250 ml
  // (Prassopoulos et al., Eur Radiol 1997: mean 215 ml).
  {
    const V3 long_axis = V3(-0.15, 0.55, -0.82).normalized();
    const V3 outward = V3(-0.75, -0.66, 0);
    const V3 middle = long_axis.cross(outward).normalized();
    add(make_ellipsoid({"spleen", V3(-88, -38, 70), V3(55, 40, 22), long_axis, middle,
                        paint_of(label::kSpleen, Fill::solid(hu::kSpleen))}));
  }

  // ---- above the diaphragm: diaphragm muscle, lung bases, heart (all outside the peritoneal cavity) -------------
  {
    auto cache = std::make_shared<ThoraxCache>();
    add(make_custom(
        [cache](const PaintContext& ctx, Slice& s) {
          const PlaneGrid& g = ctx.grid;
          const double z = s.z_mm;
          if (z < cache->z_min) return;
          // Heart: ≈ 12 × 9 × 10 cm, left of the midline; its lower half is drawn out so that its inferior
          // surface rests on the central tendon (no lung between heart and diaphragm).
          const V3 heart_c(-20, 42, 176), heart_semi(72, 55, 60);
          const double hz = (z - heart_c.z()) / (z < heart_c.z() ? 100.0 : heart_semi.z());
          for (int64_t n = 0; n < g.size(); ++n) {
            if (ctx.torso.zone[n] != kZoneCavity || z < cache->z_bottom[n]) continue;
            const int i = static_cast<int>(n % g.nx), j = static_cast<int>(n / g.nx);
            const double x = g.x(i), y = g.y(j);
            if (z <= cache->z_top[n]) {
              s.label[n] = label::kDiaphragm;
              s.hu[n] = hu::kMuscle;
              continue;
            }
            const double hx = (x - heart_c.x()) / heart_semi.x(), hy = (y - heart_c.y()) / heart_semi.y();
            if (hx * hx + hy * hy + hz * hz <= 1) {
              s.label[n] = label::kHeart;
              s.hu[n] = hu::kBlood;
            } else {
              s.label[n] = x >= 0 ? label::kLungLowerLobeRight : label::kLungLowerLobeLeft;
              // Faint vascular texture of the lung.
              s.hu[n] = hu::kLung + 80.0f * (value_noise(x, y, z, 6.0, 0x1A46ull) - 0.5f);
            }
          }
        },
        [cache](const PlaneGrid& g, const TorsoModel&) {
          // Diaphragm ≈ 5 mm thick (normal 2–5 mm at the dome; thicker at the crura), measured along the normal:
          // in z it is thicker where the dome is steep. Never thinner than a voxel.
          const double t = std::max(5.0, g.min_spacing_mm);
          cache->z_top.assign(g.size(), 0);
          cache->z_bottom.assign(g.size(), 0);
          for (int j = 0; j < g.ny; ++j)
            for (int i = 0; i < g.nx; ++i) {
              const double x = g.x(i), y = g.y(j), h = 0.5;
              const double zt = diaphragm_z(x, y);
              const double gx = (diaphragm_z(x + h, y) - diaphragm_z(x - h, y)) / (2 * h);
              const double gy = (diaphragm_z(x, y + h) - diaphragm_z(x, y - h)) / (2 * h);
              const double tv = std::min(t * std::sqrt(1 + gx * gx + gy * gy), 25.0);
              const int64_t n = int64_t(j) * g.nx + i;
              cache->z_top[n] = static_cast<float>(zt);
              cache->z_bottom[n] = static_cast<float>(zt - tv);
              cache->z_min = std::min(cache->z_min, cache->z_bottom[n]);
            }
        }));
  }

  // ---- kidneys: retroperitoneal, T12–L3, right ≈ 1–2 cm lower (liver); 11 × 6 × 4 cm, ≈ 150 ml each (ICRP 89:
  // 310 g for both in men). Long axis tilted (upper pole medial and posterior), hilum facing anteromedially.
  for (const double sx : {1.0, -1.0}) {
    const bool right = sx > 0;
    const V3 c = right ? V3(68, -50, -10) : V3(-66, -47, 8);
    const V3 long_axis = V3(-0.2 * sx, -0.25, 0.95).normalized();
    const V3 width_axis = V3(0.87 * sx, -0.5, 0);   // from the hilum to the lateral border
    const uint8_t lab = right ? label::kKidneyRight : label::kKidneyLeft;
    add(make_ellipsoid({"kidney", c, V3(55, 29, 22), long_axis, width_axis, paint_of(lab, Fill::solid(hu::kKidney))}));
    // Renal sinus fat at the hilum (medial, anterior).
    add(make_ellipsoid({"renal sinus fat", c - 14 * width_axis.normalized(), V3(28, 10, 8), long_axis, width_axis,
                        paint_of(label::kIntraperitonealFat, Fill::solid(hu::kFat + 20), kInCavity, lab)}));
  }

  // ---- iliopsoas: psoas beside the lumbar bodies from T12, thickening downwards, into the iliac fossa -----------
  for (const double sx : {1.0, -1.0}) {
    std::vector<TubeNode> n;
    const std::array<std::array<double, 2>, 6> radius{{{-126, 22}, {-87, 20}, {-48, 17}, {-12, 13}, {25, 9}, {58, 5}}};
    for (double z = 58; z >= -126 - 1e-9; z -= 12) {
      const double r = interp(radius, z);
      n.push_back({V3(sx * (body_semi_at(z).x() + r - 3), spine_y_mm(z) + (z < -60 ? 4 : -2), z), r});
    }
    n.push_back({V3(sx * 58, -28, -160), 22});
    n.push_back({V3(sx * 72, -22, -205), 20});
    add(make_tube({"psoas", n, paint_of(sx > 0 ? label::kIliopsoasRight : label::kIliopsoasLeft, Fill::solid(hu::kMuscle),
                                        kInMuscleOrCavity)}));
  }

  // ---- erector spinae (autochthonous back muscles) between the spinous processes and the rib angles -------------
  for (const double sx : {1.0, -1.0}) {
    // Squarish sections (exponent 4) that meet at the midline behind the canal; the spinous processes and
    // laminae, painted later, sit between them.
    add(make_prism({"autochthon", -200, 200, 4,
                    [sx](double z) {
                      const std::array<std::array<double, 2>, 5> ax{{{-160, 22}, {-120, 32}, {20, 32}, {70, 27}, {130, 24}}};
                      const std::array<std::array<double, 2>, 5> ay{{{-160, 12}, {-120, 23}, {20, 23}, {70, 18}, {130, 15.5}}};
                      const double sxm = interp(ax, z), sym = interp(ay, z);
                      return PrismSection{V2(sx * (sxm - 3), kPosteriorFatBoundaryY + sym), V2(sxm, sym)};
                    },
                    paint_of(sx > 0 ? label::kAutochthonRight : label::kAutochthonLeft, Fill::solid(hu::kMuscle),
                             kInMuscleOrCavity)}));
  }

  // ---- great vessels -----------------------------------------------------------------------------------------------
  add(make_tube({"IVC", ivc_nodes(), paint_of(label::kInferiorVenaCava, kBloodFill)}));
  {
    const V3 conf = ivc_nodes().front().p_mm;
    add(make_tube({"right common iliac vein", {{conf, 9}, {V3(38, -14, -150), 8}, {V3(56, -24, -205), 8}},
                   paint_of(label::kIliacVeinRight, kBloodFill)}));
    add(make_tube({"left common iliac vein",
                   {{conf, 9}, {V3(-18, conf.y() - 4, -130), 8}, {V3(-45, -16, -160), 8}, {V3(-58, -24, -205), 8}},
                   paint_of(label::kIliacVeinLeft, kBloodFill)}));
  }
  {
    const std::vector<TubeNode> ao = aorta_nodes();
    add(make_tube({"aorta", ao, paint_of(label::kAorta, kBloodFill)}));
    const V3 bif = ao.back().p_mm;
    add(make_tube({"left common iliac artery",
                   {{bif, 8}, {V3(-32, bif.y() - 3, -115), 6.5}, {V3(-50, -6, -150), 6}, {V3(-64, -14, -205), 5.5}},
                   paint_of(label::kIliacArteryLeft, kBloodFill)}));
    add(make_tube({"right common iliac artery",
                   {{bif, 8}, {V3(6, bif.y() + 1, -115), 6.5}, {V3(34, -4, -150), 6}, {V3(52, -12, -205), 5.5}},
                   paint_of(label::kIliacArteryRight, kBloodFill)}));
  }

  // ---- vertebral column ---------------------------------------------------------------------------------------------
  add(make_custom(paint_spine));

  // ---- iliac wings with the iliacus inside and the gluteus medius outside ---------------------------------------
  {
    auto cache = std::make_shared<WingCache>();
    add(make_custom(
        [cache](const PaintContext& ctx, Slice& s) {
          const double z = s.z_mm;
          if (z > kWingTopZ) return;
          const PlaneGrid& g = ctx.grid;
          const double shift = 0.35 * (kWingTopZ - z);   // the wing slopes medially below the crest
          const Fill bone = Fill::bone(hu::kCorticalBone, hu::kCancellousBone + 50, 2.0);
          for (int side = 0; side < 2; ++side) {
            const bool right = side == 0;
            for (int64_t n = 0; n < g.size(); ++n) {
              const float sarc = cache->s[side][n];
              if (sarc < 0) continue;
              const Zone zn = static_cast<Zone>(ctx.torso.zone[n]);
              if (zn != kZoneMuscle && zn != kZoneCavity) continue;
              const double crest = wing_crest_z(sarc);
              if (z > crest + 4) continue;
              const double d = cache->sd[side][n] - shift;
              const double half_t = 0.5 * (6 + 8 * (1 - sarc));   // thick posteriorly, thin in the fossa
              if (std::abs(d) <= half_t && z <= crest) {
                FillSample fs{std::min(half_t - std::abs(d), crest - z), 0, 0, z};
                s.label[n] = right ? label::kHipRight : label::kHipLeft;
                s.hu[n] = fill_hu(bone, fs, g.min_spacing_mm);
              } else if (d > half_t && d < half_t + 16 && sarc > 0.3 && z <= crest - 3) {
                s.label[n] = right ? label::kIliopsoasRight : label::kIliopsoasLeft;
                s.hu[n] = hu::kMuscle;
              } else if (d < -half_t && d > -half_t - 24 && sarc > 0.12 && sarc < 0.97 && z <= crest - 2) {
                s.label[n] = right ? label::kGluteusMediusRight : label::kGluteusMediusLeft;
                s.hu[n] = hu::kMuscle;
              }
            }
          }
        },
        [cache](const PlaneGrid& g, const TorsoModel&) {
          // Mid-surface of the right wing at crest height, from the sacro-iliac joint round the flank to the ASIS.
          const std::array<V2, 6> ctrl{V2(48, -58), V2(75, -74), V2(110, -58), V2(127, -22), V2(120, 12), V2(106, 32)};
          std::vector<V2> curve;
          for (std::size_t k = 0; k + 1 < ctrl.size(); ++k) {
            const V2 p0 = ctrl[k > 0 ? k - 1 : k], p1 = ctrl[k], p2 = ctrl[k + 1], p3 = ctrl[k + 2 < ctrl.size() ? k + 2 : k + 1];
            for (int q = 0; q < 20; ++q) {
              const double t = q / 20.0;
              curve.push_back(0.5 * ((2 * p1) + (-p0 + p2) * t + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t * t +
                                     (-p0 + 3 * p1 - 3 * p2 + p3) * t * t * t));
            }
          }
          curve.push_back(ctrl.back());
          std::vector<double> arc(curve.size(), 0);
          for (std::size_t k = 1; k < curve.size(); ++k) arc[k] = arc[k - 1] + (curve[k] - curve[k - 1]).norm();
          for (double& v : arc) v /= arc.back();
          for (int side = 0; side < 2; ++side) {
            cache->sd[side].assign(g.size(), 0);
            cache->s[side].assign(g.size(), -1);
            const double sx = side == 0 ? 1 : -1;
            for (int j = 0; j < g.ny; ++j)
              for (int i = 0; i < g.nx; ++i) {
                const V2 p(sx * g.x(i), g.y(j));   // mirror the left side onto the right curve
                if (p.x() < 20) continue;
                double best = 1e18, best_sd = 0, best_s = 0;
                for (std::size_t k = 0; k + 1 < curve.size(); ++k) {
                  const V2 a = curve[k], d = curve[k + 1] - curve[k];
                  const double t = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
                  const V2 q = a + t * d;
                  const double dist2 = (p - q).squaredNorm();
                  if (dist2 < best) {
                    best = dist2;
                    // Sign: positive on the side of the curve facing the body centre (the iliac fossa).
                    const double cross = d.x() * (p - a).y() - d.y() * (p - a).x();
                    best_sd = cross > 0 ? std::sqrt(dist2) : -std::sqrt(dist2);
                    best_s = arc[k] + t * (arc[k + 1] - arc[k]);
                  }
                }
                if (std::sqrt(best) > 80) continue;
                const int64_t n = int64_t(j) * g.nx + i;
                cache->sd[side][n] = static_cast<float>(best_sd);
                cache->s[side][n] = static_cast<float>(best_s);
              }
          }
        }));
  }

  // ---- ribs 7–12 with the costal cartilages of 7–10, and the sternum/xiphoid -------------------------------------
  const Fill rib_bone = Fill::bone(hu::kCorticalBone, hu::kCancellousBone + 50, 1.5);
  for (const RibSpec& r : kRibs) {
    for (const double sx : {1.0, -1.0}) {
      const uint8_t lab = sx > 0 ? label::rib_right(r.n) : label::rib_left(r.n);
      add(make_tube({"rib", rib_nodes(torso, r, sx, false), paint_of(lab, rib_bone, kUnderSkin)}));
      if (r.psi_cartilage_end_deg > r.psi_bone_end_deg)
        add(make_tube({"costal cartilage", rib_nodes(torso, r, sx, true),
                       paint_of(label::kCostalCartilages, Fill::solid(hu::kCartilage), kUnderSkin)}));
    }
  }
  add(make_prism({"sternum and xiphoid", 128, 260, 4,
                  [](double z) {
                    const double u = smoothstep(150, 168, z);   // xiphoid below, sternal body above
                    return PrismSection{V2(0, 110 - 2 - 18 - 7), V2(9 + 7 * u, 4 + 2 * u)};
                  },
                  paint_of(label::kSternum, Fill::bone(hu::kCorticalBone, hu::kSternum, 1.0), kUnderSkin)}));
  return a;
}

}  // namespace pneumo::phantom_detail
