#include "evaluate/landmarks.h"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "core/error.h"

namespace pneumo {

RigidTransform horn_rigid(const std::vector<Vec3>& p, const std::vector<Vec3>& q) {
  if (p.size() != q.size() || p.size() < 3)
    throw InputError("rigid alignment needs at least 3 point pairs; got " + std::to_string(std::min(p.size(), q.size())));
  const double n = double(p.size());
  Vec3 cp = Vec3::Zero(), cq = Vec3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) {
    cp += p[i] / n;
    cq += q[i] / n;
  }
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();   // S_ab = Σ p'_a q'_b
  double spread = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    S += (p[i] - cp) * (q[i] - cq).transpose();
    spread = std::max(spread, (p[i] - cp).norm());
  }
  // Collinear (or coincident) points: the second singular value of the centred points vanishes.
  Eigen::Matrix3d spread_matrix = Eigen::Matrix3d::Zero();
  for (const Vec3& x : p) spread_matrix += (x - cp) * (x - cp).transpose();
  const Eigen::Vector3d sv = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(spread_matrix).eigenvalues();
  if (!(spread > 0.0) || sv[1] < 1e-10 * sv[2])
    throw InputError("rigid alignment: the measured points lie on a line; the rotation about it is undetermined");
  // Horn's symmetric 4×4 matrix; its largest eigenvector is the rotation quaternion (w, x, y, z).
  Eigen::Matrix4d N;
  N << S(0, 0) + S(1, 1) + S(2, 2), S(1, 2) - S(2, 1), S(2, 0) - S(0, 2), S(0, 1) - S(1, 0),
      S(1, 2) - S(2, 1), S(0, 0) - S(1, 1) - S(2, 2), S(0, 1) + S(1, 0), S(2, 0) + S(0, 2),
      S(2, 0) - S(0, 2), S(0, 1) + S(1, 0), -S(0, 0) + S(1, 1) - S(2, 2), S(1, 2) + S(2, 1),
      S(0, 1) - S(1, 0), S(2, 0) + S(0, 2), S(1, 2) + S(2, 1), -S(0, 0) - S(1, 1) + S(2, 2);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(N);
  const Eigen::Vector4d v = eig.eigenvectors().col(3);
  const Eigen::Quaterniond quat(v[0], v[1], v[2], v[3]);
  RigidTransform out;
  out.R = quat.normalized().toRotationMatrix();
  out.t = cq - out.R * cp;
  return out;
}

LandmarkEvaluation evaluate_landmarks(const std::vector<Landmark>& marks, const PointMapFn& map) {
  LandmarkEvaluation e;
  std::vector<Vec3> before_tracker, before_ct;
  for (const Landmark& m : marks) {
    LandmarkResult r;
    r.name = m.name;
    r.ct_mm = m.ct_mm;
    r.simulated_mm = map(m.ct_mm);
    r.measured = m.measured_before_mm && m.measured_after_mm;
    if (r.measured) {
      before_tracker.push_back(*m.measured_before_mm);
      before_ct.push_back(m.ct_mm);
    }
    e.points.push_back(r);
  }
  if (before_tracker.empty()) return e;
  e.measured = true;
  e.tracker_to_ct = horn_rigid(before_tracker, before_ct);
  double sq = 0.0;
  for (std::size_t i = 0; i < before_tracker.size(); ++i)
    sq += (e.tracker_to_ct.apply(before_tracker[i]) - before_ct[i]).squaredNorm();
  e.alignment_rms_mm = std::sqrt(sq / double(before_tracker.size()));
  int count = 0;
  for (std::size_t i = 0; i < marks.size(); ++i) {
    LandmarkResult& r = e.points[i];
    if (!r.measured) continue;
    r.measured_after_ct_mm = e.tracker_to_ct.apply(*marks[i].measured_after_mm);
    e.position_error_mm += (r.simulated_mm - r.measured_after_ct_mm).norm();
    // (simulated − CT) − (measured − CT) = simulated − measured, axis by axis.
    e.displacement_error_mm += (r.simulated_mm - r.measured_after_ct_mm).cwiseAbs();
    ++count;
  }
  e.position_error_mm /= count;
  e.displacement_error_mm /= count;
  return e;
}

nlohmann::json to_json(const LandmarkEvaluation& e) {
  auto vec = [](const Vec3& v) { return nlohmann::json::array({v[0], v[1], v[2]}); };
  nlohmann::json points = nlohmann::json::array();
  for (const LandmarkResult& r : e.points) {
    nlohmann::json p = {{"name", r.name}, {"ct_mm", vec(r.ct_mm)}, {"simulated_mm", vec(r.simulated_mm)},
                        {"displacement_mm", vec(r.simulated_mm - r.ct_mm)},
                        {"displacement_norm_mm", (r.simulated_mm - r.ct_mm).norm()}};
    if (r.measured) {
      p["measured_after_ct_mm"] = vec(r.measured_after_ct_mm);
      p["error_mm"] = (r.simulated_mm - r.measured_after_ct_mm).norm();
    }
    points.push_back(p);
  }
  nlohmann::json j = {{"points", points}, {"measured", e.measured}};
  if (e.measured) {
    j["alignment_rms_mm"] = e.alignment_rms_mm;
    j["position_error_mm"] = e.position_error_mm;
    j["displacement_error_mm"] = {{"horizontal", e.displacement_error_mm[0]},
                                  {"ventrodorsal", e.displacement_error_mm[1]},
                                  {"cephalocaudal", e.displacement_error_mm[2]}};
  }
  return j;
}

}  // namespace pneumo
