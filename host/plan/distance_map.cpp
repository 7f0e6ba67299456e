#include "plan/distance_map.h"

#include <cmath>
#include <limits>
#include <array>
#include <stdexcept>

namespace pneumo {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// One pass along a line of n samples f (squared distances so far), spacing h: d[q] = min_p f[p] +
/// (h·(q − p))². The lower envelope of the parabolas rooted at each finite f[p] (FH 2012, Alg. 1).
void squared_distance_1d(const double* f, double* d, int64_t n, double h, std::vector<int64_t>& v,
                         std::vector<double>& z) {
  v.assign(std::size_t(n), 0);
  z.assign(std::size_t(n) + 1, 0.0);
  const double h2 = h * h;
  int64_t k = -1;
  for (int64_t q = 0; q < n; ++q) {
    if (!std::isfinite(f[q])) continue;
    if (k < 0) {
      k = 0;
      v[0] = q;
      z[0] = -kInf;
      z[1] = kInf;
      continue;
    }
    double s;
    for (;;) {
      const int64_t p = v[std::size_t(k)];
      // Where the parabolas of p and q cross (in index units).
      s = ((f[q] + h2 * double(q) * double(q)) - (f[p] + h2 * double(p) * double(p))) / (2.0 * h2 * double(q - p));
      if (k > 0 && s <= z[std::size_t(k)]) --k;   // p's parabola is nowhere the lowest: drop it
      else break;
    }
    ++k;
    v[std::size_t(k)] = q;
    z[std::size_t(k)] = s;
    z[std::size_t(k) + 1] = kInf;
  }
  if (k < 0) {
    for (int64_t q = 0; q < n; ++q) d[q] = kInf;
    return;
  }
  int64_t j = 0;
  for (int64_t q = 0; q < n; ++q) {
    while (z[std::size_t(j) + 1] < double(q)) ++j;
    const int64_t p = v[std::size_t(j)];
    const double dq = h * double(q - p);
    d[q] = dq * dq + f[p];
  }
}

}  // namespace

std::vector<float> distance_to_mask_mm(const std::vector<uint8_t>& mask, const Geometry& g) {
  if (int64_t(mask.size()) != g.voxel_count()) throw std::invalid_argument("distance_to_mask_mm: mask size");
  if (mask.empty()) return {};
  const int64_t nx = g.dims[0], ny = g.dims[1];
  // Squared distances in float (4 bytes a voxel on clinical grids); each line's envelope in double.
  std::vector<float> d2(mask.size());
  for (std::size_t n = 0; n < mask.size(); ++n) d2[n] = mask[n] ? 0.0f : std::numeric_limits<float>::infinity();
  const std::array<int64_t, 3> stride{1, nx, nx * ny};
  for (int axis = 0; axis < 3; ++axis) {
    const int64_t n = g.dims[std::size_t(axis)];
    const double h = g.spacing_mm[axis];
    const int64_t lines = g.voxel_count() / n;
    // Every line along `axis`: a start index per line, its samples `stride` apart.
#pragma omp parallel
    {
      std::vector<double> f(std::size_t(n), 0.0), d(std::size_t(n), 0.0), z;
      std::vector<int64_t> v;
#pragma omp for schedule(static)
      for (int64_t line = 0; line < lines; ++line) {
        int64_t start;
        if (axis == 0) start = line * nx;
        else if (axis == 1) start = (line / nx) * nx * ny + line % nx;
        else start = line;
        for (int64_t q = 0; q < n; ++q) f[std::size_t(q)] = d2[std::size_t(start + q * stride[std::size_t(axis)])];
        squared_distance_1d(f.data(), d.data(), n, h, v, z);
        for (int64_t q = 0; q < n; ++q) d2[std::size_t(start + q * stride[std::size_t(axis)])] = float(d[std::size_t(q)]);
      }
    }
  }
  std::vector<float> out(mask.size());
  for (std::size_t k = 0; k < mask.size(); ++k) out[k] = std::sqrt(d2[k]);
  return out;
}

}  // namespace pneumo
