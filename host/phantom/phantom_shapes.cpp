// Primitives of the synthetic abdomen: the torso model and its per-column maps, fills, noise, and the painting of
// ellipsoids, tubes and prisms into one axial slice. See phantom_model.h for the overall scheme.
#include <algorithm>
#include <cmath>
#include <limits>

#include "phantom/phantom_model.h"

namespace pneumo::phantom_detail {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr float kNoDepth = -std::numeric_limits<float>::infinity();

uint64_t splitmix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

uint64_t hash3(int64_t a, int64_t b, int64_t c, uint64_t seed) {
  uint64_t h = splitmix64(seed ^ static_cast<uint64_t>(a));
  h = splitmix64(h ^ static_cast<uint64_t>(b));
  return splitmix64(h ^ static_cast<uint64_t>(c));
}

double unit_from_hash(uint64_t h) { return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0); }

double smoothstep01(double t) { return t * t * (3 - 2 * t); }
}  // namespace

// ---- grid ----------------------------------------------------------------------------------------------------------
int PlaneGrid::i_first(double lo_mm) const { return std::max(0, static_cast<int>(std::ceil((lo_mm - x0_mm) / dx_mm))); }
int PlaneGrid::i_last(double hi_mm) const { return std::min(nx - 1, static_cast<int>(std::floor((hi_mm - x0_mm) / dx_mm))); }
int PlaneGrid::j_first(double lo_mm) const { return std::max(0, static_cast<int>(std::ceil((lo_mm - y0_mm) / dy_mm))); }
int PlaneGrid::j_last(double hi_mm) const { return std::min(ny - 1, static_cast<int>(std::floor((hi_mm - y0_mm) / dy_mm))); }

void Slice::resize(int64_t n) {
  label.assign(n, 0);
  hu.assign(n, 0.0f);
  scratch_depth.assign(n, kNoDepth);
  scratch_seg.assign(n, -1);
}

// ---- noise ---------------------------------------------------------------------------------------------------------
float voxel_noise(int64_t i, int64_t j, int64_t k) {
  // Irwin–Hall: the sum of four 16-bit uniforms is close to Gaussian; centred and scaled to σ = 1.
  const uint64_t h = hash3(i, j, k, 0x5eed0f0a11ce5ull);
  double sum = 0;
  for (int q = 0; q < 4; ++q) sum += static_cast<double>((h >> (16 * q)) & 0xFFFFu) * (1.0 / 65536.0);
  return static_cast<float>((sum - 2.0) * 1.7320508075688772);   // var(U) = 1/12, ×4 = 1/3
}

float value_noise(double x_mm, double y_mm, double z_mm, double cell_mm, uint64_t seed) {
  const double fx = x_mm / cell_mm, fy = y_mm / cell_mm, fz = z_mm / cell_mm;
  const double flx = std::floor(fx), fly = std::floor(fy), flz = std::floor(fz);
  const int64_t ix = static_cast<int64_t>(flx), iy = static_cast<int64_t>(fly), iz = static_cast<int64_t>(flz);
  const double tx = smoothstep01(fx - flx), ty = smoothstep01(fy - fly), tz = smoothstep01(fz - flz);
  double v[2][2][2];
  for (int c = 0; c < 2; ++c)
    for (int b = 0; b < 2; ++b)
      for (int a = 0; a < 2; ++a) v[c][b][a] = unit_from_hash(hash3(ix + a, iy + b, iz + c, seed));
  auto lerp = [](double p, double q, double t) { return p + (q - p) * t; };
  const double y0 = lerp(lerp(v[0][0][0], v[0][0][1], tx), lerp(v[0][1][0], v[0][1][1], tx), ty);
  const double y1 = lerp(lerp(v[1][0][0], v[1][0][1], tx), lerp(v[1][1][0], v[1][1][1], tx), ty);
  return static_cast<float>(lerp(y0, y1, tz));
}

// ---- fills ---------------------------------------------------------------------------------------------------------
namespace {
float rim_blend(float rim_hu, float inner_hu, double rim_mm, double min_spacing_mm) {
  const double eff = std::max(rim_mm, min_spacing_mm);
  return static_cast<float>(inner_hu + (rim_hu - inner_hu) * (rim_mm / eff));
}

float contents_hu(const Fill& f, const FillSample& s) {
  switch (f.content) {
    case Content::Fluid: return f.hu_inner;
    case Content::GasCap: return s.y_above_axis_mm > f.gas_level * s.radius_mm ? hu::kGas : f.hu_inner;
    case Content::GasAbovePlane: return s.y_mm > f.gas_level ? hu::kGas : f.hu_inner;
    case Content::Stool: {
      // Faeces: gas bubbles of a few mm in a mottled matrix (the typical appearance in an unprepared colon).
      if (value_noise(s.x_mm, s.y_mm, s.z_mm, 5.0, 0xC01Cull) > 0.70f) return hu::kGas;
      return f.hu_inner + 50.0f * (value_noise(s.x_mm, s.y_mm, s.z_mm, 3.0, 0x5700ull) - 0.5f);
    }
  }
  return f.hu_inner;
}
}  // namespace

float fill_hu(const Fill& f, const FillSample& s, double min_spacing_mm) {
  switch (f.kind) {
    case Fill::Kind::Solid: return f.hu;
    case Fill::Kind::Bone:
      if (s.depth_mm < std::max<double>(f.rim_mm, min_spacing_mm))
        return rim_blend(f.hu, f.hu_inner, f.rim_mm, min_spacing_mm);
      return f.hu_inner;
    case Fill::Kind::Hollow: {
      const float inner = contents_hu(f, s);
      if (s.depth_mm < std::max<double>(f.rim_mm, min_spacing_mm))
        return rim_blend(f.hu, inner, f.rim_mm, min_spacing_mm);
      return inner;
    }
  }
  return f.hu;
}

// ---- torso ---------------------------------------------------------------------------------------------------------
V2 TorsoModel::outline(double theta) const {
  const double c = std::cos(theta), s = std::sin(theta);
  const double n = s >= 0 ? n_anterior : n_posterior;
  const double norm = std::pow(std::pow(std::abs(c) / semi_lateral_mm, n) + std::pow(std::abs(s) / semi_ap_mm, n), 1.0 / n);
  return V2(c, s) / norm;
}

double TorsoModel::skin_mm(double min_spacing_mm) const { return std::max(skin_nominal_mm, min_spacing_mm); }

double TorsoModel::subcut_fat_mm(double theta) const {
  // Subcutaneous fat of normal-weight adults on CT: ≈ 15–25 mm anteriorly at the umbilicus, thinner over the
  // flanks, intermediate over the back; here 18 / 10 / 14 mm.
  const double s = std::sin(theta);
  const double ant = std::max(0.0, s), post = std::max(0.0, -s);
  return 10.0 + 8.0 * ant * ant + 4.0 * post * post;
}

double TorsoModel::muscle_mm(double theta, double x_b_mm) const {
  // Rectus abdominis ≈ 10 mm thick and 60–80 mm wide either side of a 10–15 mm linea alba; the external oblique,
  // internal oblique and transversus together ≈ 10–15 mm (ultrasound norms, e.g. Rankin et al., Muscle Nerve 2006).
  const double s = std::sin(theta);
  const double ax = std::abs(x_b_mm);
  if (s > 0) {
    // Linea alba 3 mm, widening over the rounded medial border of each rectus.
    const double medial = std::clamp((ax - 5.0) / 9.0, 0.0, 1.0);
    const double rectus = 3.0 + 7.0 * medial * medial * (3 - 2 * medial);
    const double t = std::clamp((ax - 75.0) / 15.0, 0.0, 1.0);   // semilunar line: rectus → flat muscles
    return rectus + 3.0 * t;
  }
  return 13.0 + 3.0 * (-s);                          // flanks → back (latissimus, quadratus lumborum)
}

void TorsoMaps::build(const TorsoModel& torso, const PlaneGrid& g) {
  const int64_t n = g.size();
  zone.assign(n, kZoneOut);
  base_label.assign(n, label::kBackground);
  base_hu.assign(n, hu::kAir);
  depth_mm.assign(n, -1e9f);

  // The skin outline sampled by angle; per sample the layer thicknesses of that point of the wall.
  constexpr int M = 4096;
  std::vector<V2> pts(M);
  std::vector<double> fat(M), muscle(M), theta(M);
  for (int m = 0; m < M; ++m) {
    theta[m] = 2 * kPi * m / M;
    pts[m] = torso.outline(theta[m]);
    fat[m] = torso.subcut_fat_mm(theta[m]);
    muscle[m] = torso.muscle_mm(theta[m], pts[m].x());
  }
  const double skin = torso.skin_mm(g.min_spacing_mm);
  const float skin_hu = hu::kFat + (hu::kSkin - hu::kFat) * static_cast<float>(torso.skin_nominal_mm / skin);

#pragma omp parallel for schedule(static)
  for (int j = 0; j < g.ny; ++j) {
    for (int i = 0; i < g.nx; ++i) {
      const V2 p(g.x(i), g.y(j));
      const double th = std::atan2(p.y(), p.x());
      const int m0 = static_cast<int>(std::lround(th / (2 * kPi) * M));
      // Nearest outline point: coarse search over ±90° around the pixel's own angle, then refine.
      auto dist2 = [&](int m) { return (pts[((m % M) + M) % M] - p).squaredNorm(); };
      int best = m0;
      double bd = dist2(m0);
      for (int d = -M / 4; d <= M / 4; d += 8)
        if (const double q = dist2(m0 + d); q < bd) { bd = q; best = m0 + d; }
      const int coarse = best;
      for (int d = -8; d <= 8; ++d)
        if (const double q = dist2(coarse + d); q < bd) { bd = q; best = coarse + d; }
      best = ((best % M) + M) % M;

      const double ns = p.y() >= 0 ? torso.n_anterior : torso.n_posterior;
      const double inside_norm = std::pow(std::abs(p.x()) / torso.semi_lateral_mm, ns) +
                                 std::pow(std::abs(p.y()) / torso.semi_ap_mm, ns);
      const double depth = inside_norm < 1.0 ? std::sqrt(bd) : -std::sqrt(bd);
      const int64_t q = int64_t(j) * g.nx + i;
      depth_mm[q] = static_cast<float>(depth);
      if (depth < 0) continue;
      const double fat_end = skin + fat[best], muscle_end = fat_end + muscle[best];
      if (depth < skin) {
        zone[q] = kZoneSkin; base_label[q] = label::kSkin; base_hu[q] = skin_hu;
      } else if (depth < fat_end) {
        zone[q] = kZoneSubcut; base_label[q] = label::kSubcutaneousFat; base_hu[q] = hu::kFat;
      } else if (depth < muscle_end) {
        zone[q] = kZoneMuscle; base_label[q] = label::kAbdominalWallMuscle; base_hu[q] = hu::kMuscle;
        // Thin fat planes between external oblique, internal oblique and transversus (lateral wall only).
        const double s = std::sin(theta[best]);
        if (std::abs(pts[best].x()) > 90.0 && s > -0.4) {
          const double u = (depth - fat_end) / muscle[best];
          const double half_plane = 0.6 / muscle[best];
          if (std::abs(u - 1.0 / 3) < half_plane || std::abs(u - 2.0 / 3) < half_plane) base_hu[q] = hu::kFat + 10;
        }
      } else {
        zone[q] = kZoneCavity; base_label[q] = label::kIntraperitonealFat; base_hu[q] = hu::kMesentericFat;
      }
    }
  }
}

// ---- ellipsoid -----------------------------------------------------------------------------------------------------
namespace {
class Ellipsoid final : public Shape {
 public:
  explicit Ellipsoid(const EllipsoidSpec& s) : spec_(s) {
    const V3 a1 = s.axis1.normalized();
    V3 a2 = s.axis2_hint - s.axis2_hint.dot(a1) * a1;
    a2.normalize();
    const V3 a3 = a1.cross(a2);
    Eigen::Matrix3d r;
    r.col(0) = a1; r.col(1) = a2; r.col(2) = a3;
    // q = M (p − c) has |q| = 1 on the surface.
    m_ = s.semi_mm.cwiseInverse().asDiagonal() * r.transpose();
    for (int a = 0; a < 3; ++a) half_[a] = std::sqrt((r.row(a).transpose().cwiseProduct(s.semi_mm)).squaredNorm());
    min_semi_ = s.semi_mm.minCoeff();
  }

  void paint(const PaintContext& ctx, Slice& sl) const override {
    const V3& c = spec_.centre_mm;
    const double dz = sl.z_mm - c.z();
    if (std::abs(dz) > half_[2]) return;
    const PlaneGrid& g = ctx.grid;
    const V3 mx = m_.col(0), my = m_.col(1), mz = m_.col(2);
    const double a = mx.squaredNorm();
    for (int j = g.j_first(c.y() - half_[1]); j <= g.j_last(c.y() + half_[1]); ++j) {
      const V3 q_row = my * (g.y(j) - c.y()) + mz * dz;   // q at x = c.x
      // |q_row + mx t|² ≤ 1 with t = x − c.x: a t² + 2 b t + (|q_row|² − 1) ≤ 0.
      const double b = q_row.dot(mx), cc = q_row.squaredNorm() - 1.0;
      const double disc = b * b - a * cc;
      if (disc < 0) continue;
      const double root = std::sqrt(disc);
      const double t0 = (-b - root) / a, t1 = (-b + root) / a;
      const int i0 = g.i_first(c.x() + t0), i1 = g.i_last(c.x() + t1);
      for (int i = i0; i <= i1; ++i) {
        const int64_t n = int64_t(j) * g.nx + i;
        if (!paint_allowed(spec_.paint, ctx, sl, n)) continue;
        const double t = g.x(i) - c.x();
        const double f = (q_row + mx * t).squaredNorm();
        FillSample fs{(1.0 - std::sqrt(f)) * min_semi_, g.x(i), g.y(j), sl.z_mm};
        sl.label[n] = spec_.paint.label;
        sl.hu[n] = fill_hu(spec_.paint.fill, fs, g.min_spacing_mm);
      }
    }
  }

 private:
  EllipsoidSpec spec_;
  Eigen::Matrix3d m_;
  double half_[3];
  double min_semi_;
};

// ---- tube ----------------------------------------------------------------------------------------------------------
class Tube final : public Shape {
 public:
  explicit Tube(TubeSpec s) : spec_(std::move(s)) {
    for (std::size_t n = 0; n + 1 < spec_.nodes.size(); ++n) {
      Seg g;
      g.a = spec_.nodes[n].p_mm;
      g.d = spec_.nodes[n + 1].p_mm - g.a;
      g.ra = spec_.nodes[n].r_mm;
      g.rb = spec_.nodes[n + 1].r_mm;
      g.len2 = std::max(g.d.squaredNorm(), 1e-12);
      g.rmax = std::max(g.ra, g.rb);
      g.z_lo = std::min(g.a.z(), g.a.z() + g.d.z()) - g.rmax;
      g.z_hi = std::max(g.a.z(), g.a.z() + g.d.z()) + g.rmax;
      g.gas = spec_.nodes[n].gas;
      segs_.push_back(g);
    }
    gas_fill_ = spec_.paint.fill;
    gas_fill_.content = Content::GasCap;
    gas_fill_.gas_level = spec_.gas_cap_level;
  }

  void paint(const PaintContext& ctx, Slice& sl) const override {
    const PlaneGrid& g = ctx.grid;
    const double z = sl.z_mm;
    int bi0 = g.nx, bi1 = -1, bj0 = g.ny, bj1 = -1;   // union of the touched boxes
    for (std::size_t s = 0; s < segs_.size(); ++s) {
      const Seg& sg = segs_[s];
      if (z < sg.z_lo || z > sg.z_hi) continue;
      // The part of the axis within rmax of this plane, and its xy box grown by rmax.
      double t0 = 0, t1 = 1;
      if (std::abs(sg.d.z()) > 1e-9) {
        t0 = (z - sg.rmax - sg.a.z()) / sg.d.z();
        t1 = (z + sg.rmax - sg.a.z()) / sg.d.z();
        if (t0 > t1) std::swap(t0, t1);
        t0 = std::clamp(t0, 0.0, 1.0);
        t1 = std::clamp(t1, 0.0, 1.0);
      }
      const V3 p0 = sg.a + t0 * sg.d, p1 = sg.a + t1 * sg.d;
      const int i0 = g.i_first(std::min(p0.x(), p1.x()) - sg.rmax), i1 = g.i_last(std::max(p0.x(), p1.x()) + sg.rmax);
      const int j0 = g.j_first(std::min(p0.y(), p1.y()) - sg.rmax), j1 = g.j_last(std::max(p0.y(), p1.y()) + sg.rmax);
      if (i0 > i1 || j0 > j1) continue;
      bi0 = std::min(bi0, i0); bi1 = std::max(bi1, i1); bj0 = std::min(bj0, j0); bj1 = std::max(bj1, j1);
      for (int j = j0; j <= j1; ++j) {
        for (int i = i0; i <= i1; ++i) {
          const V3 p(g.x(i), g.y(j), z);
          const V3 ap = p - sg.a;
          const double t = std::clamp(ap.dot(sg.d) / sg.len2, 0.0, 1.0);
          const double dist = (ap - t * sg.d).norm();
          const float depth = static_cast<float>(sg.ra + t * (sg.rb - sg.ra) - dist);
          const int64_t n = int64_t(j) * g.nx + i;
          if (depth > sl.scratch_depth[n]) { sl.scratch_depth[n] = depth; sl.scratch_seg[n] = static_cast<int32_t>(s); }
        }
      }
    }
    for (int j = bj0; j <= bj1; ++j) {
      for (int i = bi0; i <= bi1; ++i) {
        const int64_t n = int64_t(j) * g.nx + i;
        const float depth = sl.scratch_depth[n];
        if (depth > 0 && paint_allowed(spec_.paint, ctx, sl, n)) {
          const Seg& sg = segs_[sl.scratch_seg[n]];
          const V3 p(g.x(i), g.y(j), z);
          const double t = std::clamp((p - sg.a).dot(sg.d) / sg.len2, 0.0, 1.0);
          const V3 axis = sg.a + t * sg.d;
          FillSample fs{depth, p.x(), p.y(), z, p.y() - axis.y(), sg.ra + t * (sg.rb - sg.ra)};
          sl.label[n] = spec_.paint.label;
          sl.hu[n] = fill_hu(sg.gas ? gas_fill_ : spec_.paint.fill, fs, g.min_spacing_mm);
        }
        sl.scratch_depth[n] = kNoDepth;
        sl.scratch_seg[n] = -1;
      }
    }
  }

 private:
  struct Seg {
    V3 a, d;
    double ra, rb, len2, rmax, z_lo, z_hi;
    bool gas;
  };
  TubeSpec spec_;
  std::vector<Seg> segs_;
  Fill gas_fill_;
};

// ---- prism ---------------------------------------------------------------------------------------------------------
class Prism final : public Shape {
 public:
  explicit Prism(PrismSpec s) : spec_(std::move(s)) {}

  void paint(const PaintContext& ctx, Slice& sl) const override {
    const double z = sl.z_mm;
    if (z < spec_.z_lo_mm || z > spec_.z_hi_mm) return;
    const PrismSection sec = spec_.section(z);
    if (!sec.valid || sec.semi_mm.x() <= 0 || sec.semi_mm.y() <= 0) return;
    const PlaneGrid& g = ctx.grid;
    const double cap = std::min(z - spec_.z_lo_mm, spec_.z_hi_mm - z);
    const double min_semi = sec.semi_mm.minCoeff();
    const double ix = 1.0 / sec.semi_mm.x(), iy = 1.0 / sec.semi_mm.y();
    for (int j = g.j_first(sec.centre_mm.y() - sec.semi_mm.y()); j <= g.j_last(sec.centre_mm.y() + sec.semi_mm.y()); ++j) {
      const double v = (g.y(j) - sec.centre_mm.y()) * iy;
      const double v2 = v * v;
      for (int i = g.i_first(sec.centre_mm.x() - sec.semi_mm.x()); i <= g.i_last(sec.centre_mm.x() + sec.semi_mm.x()); ++i) {
        const double u = (g.x(i) - sec.centre_mm.x()) * ix;
        const double u2 = u * u;
        const double f = spec_.exponent == 4 ? u2 * u2 + v2 * v2 : u2 + v2;
        if (f > 1.0) continue;
        const int64_t n = int64_t(j) * g.nx + i;
        if (!paint_allowed(spec_.paint, ctx, sl, n)) continue;
        const double radial = spec_.exponent == 4 ? std::sqrt(std::sqrt(f)) : std::sqrt(f);
        FillSample fs{std::min((1.0 - radial) * min_semi, cap), g.x(i), g.y(j), z};
        sl.label[n] = spec_.paint.label;
        sl.hu[n] = fill_hu(spec_.paint.fill, fs, g.min_spacing_mm);
      }
    }
  }

 private:
  PrismSpec spec_;
};

class Custom final : public Shape {
 public:
  Custom(std::function<void(const PaintContext&, Slice&)> p, std::function<void(const PlaneGrid&, const TorsoModel&)> prep)
      : paint_(std::move(p)), prepare_(std::move(prep)) {}
  void paint(const PaintContext& ctx, Slice& sl) const override { paint_(ctx, sl); }
  void prepare(const PlaneGrid& g, const TorsoModel& t) override { if (prepare_) prepare_(g, t); }

 private:
  std::function<void(const PaintContext&, Slice&)> paint_;
  std::function<void(const PlaneGrid&, const TorsoModel&)> prepare_;
};
}  // namespace

std::unique_ptr<Shape> make_ellipsoid(const EllipsoidSpec& spec) { return std::make_unique<Ellipsoid>(spec); }
std::unique_ptr<Shape> make_tube(TubeSpec spec) { return std::make_unique<Tube>(std::move(spec)); }
std::unique_ptr<Shape> make_prism(PrismSpec spec) { return std::make_unique<Prism>(std::move(spec)); }
std::unique_ptr<Shape> make_custom(std::function<void(const PaintContext&, Slice&)> paint,
                                   std::function<void(const PlaneGrid&, const TorsoModel&)> prepare) {
  return std::make_unique<Custom>(std::move(paint), std::move(prepare));
}

}  // namespace pneumo::phantom_detail
