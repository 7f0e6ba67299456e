#include "anatomy/distance_transform.h"

#include <cmath>
#include <limits>

namespace pneumo {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Squared distances along one line: d[q] = min_p ((q - p)·h)² + f[p]. f = +inf marks "no site".
/// v, z: scratch of n and n+1 entries.
void edt_line(const double* f, int64_t n, double h, double* d, int64_t* v, double* z) {
  int64_t k = -1;
  for (int64_t q = 0; q < n; ++q) {
    if (f[q] == kInf) continue;
    const double fq = f[q] + (q * h) * (q * h);
    double s = -kInf;
    while (k >= 0) {
      const double p = double(v[k]) * h;
      s = (fq - (f[v[k]] + p * p)) / (2.0 * h * double(q - v[k]));  // where the parabolas cross (mm)
      if (s <= z[k]) --k;
      else break;
    }
    ++k;
    v[k] = q;
    z[k] = k == 0 ? -kInf : s;
    z[k + 1] = kInf;
  }
  if (k < 0) {
    for (int64_t q = 0; q < n; ++q) d[q] = kInf;
    return;
  }
  int64_t j = 0;
  for (int64_t q = 0; q < n; ++q) {
    while (z[j + 1] < q * h) ++j;
    const double dq = double(q - v[j]) * h;
    d[q] = dq * dq + f[v[j]];
  }
}

/// One pass along `axis` over the whole grid, in place on squared distances.
void edt_pass(std::vector<float>& sq, const Geometry& g, int axis) {
  const int64_t stride[3] = {1, g.dims[0], g.dims[0] * g.dims[1]};
  const int b = axis == 0 ? 1 : 0, c = 3 - axis - b;   // the other two axes; b = 0 unless axis is 0
  const int64_t n = g.dims[axis], st = stride[axis];
  const double h = g.spacing_mm[axis];
#pragma omp parallel
  {
    std::vector<double> f(static_cast<std::size_t>(n)), d(static_cast<std::size_t>(n)), z(std::size_t(n) + 1);
    std::vector<int64_t> v(static_cast<std::size_t>(n));
    // Lines adjacent in axis b (i when possible) touch the same cache lines one after another.
#pragma omp for schedule(static)
    for (int64_t ic = 0; ic < g.dims[c]; ++ic)
      for (int64_t ib = 0; ib < g.dims[b]; ++ib) {
        float* line = sq.data() + ib * stride[b] + ic * stride[c];
        for (int64_t q = 0; q < n; ++q) {
          const float x = line[q * st];
          f[q] = x == std::numeric_limits<float>::infinity() ? kInf : double(x);
        }
        edt_line(f.data(), n, h, d.data(), v.data(), z.data());
        for (int64_t q = 0; q < n; ++q) line[q * st] = float(d[q]);
      }
  }
}

}  // namespace

std::vector<float> distance_to_outside_mm(const std::vector<uint8_t>& inside, const Geometry& g) {
  const int64_t n = g.voxel_count();
  std::vector<float> dist(static_cast<std::size_t>(n));
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < n; ++i) dist[i] = inside[i] ? std::numeric_limits<float>::infinity() : 0.0f;
  for (int axis = 0; axis < 3; ++axis) edt_pass(dist, g, axis);
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < n; ++i) dist[i] = std::sqrt(dist[i]);
  return dist;
}

}  // namespace pneumo
