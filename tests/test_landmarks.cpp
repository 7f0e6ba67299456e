// Landmark evaluation (method.md §9): Horn's closed-form rigid alignment and the errors built on it.
#include <gtest/gtest.h>

#include <random>

#include "core/error.h"
#include "evaluate/landmarks.h"
#include "seed_support.h"

using namespace pneumo;

namespace {
RigidTransform random_rigid(std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  RigidTransform T;
  T.R = Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
  T.t = Vec3(g(rng), g(rng), g(rng)) * 100.0;
  return T;
}
}  // namespace

TEST(Landmarks, HornRecoversARigidMotionExactly) {
  // Compared: the recovered R, t against the motion that made the points (random, a fixed seed (seed_support.h)), for
  // 3 to 20 noise-free points. Tolerance 1e-9 (R) and 1e-7 mm (t, points ~100 mm): double rounding only.
  const unsigned seed = testing_support::test_seed(20261212u);
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-150.0, 150.0);
  for (int n : {3, 4, 7, 20}) {
    const RigidTransform T = random_rigid(rng);
    std::vector<Vec3> p, q;
    for (int i = 0; i < n; ++i) {
      p.push_back(Vec3(u(rng), u(rng), u(rng)));
      q.push_back(T.apply(p.back()));
    }
    const RigidTransform H = horn_rigid(p, q);
    EXPECT_LE((H.R - T.R).cwiseAbs().maxCoeff(), 1e-9) << n << " points";
    EXPECT_LE((H.t - T.t).norm(), 1e-7) << n << " points";
    EXPECT_NEAR(H.R.determinant(), 1.0, 1e-12);   // a rotation, never a reflection
  }
}

TEST(Landmarks, HornIsTheLeastSquaresFitUnderNoise) {
  // Compared: with noisy points, Horn's residual against the residual of the true motion and of small
  // perturbations of Horn's answer: the closed form must be the minimum (no perturbation does better).
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-100.0, 100.0);
  std::normal_distribution<double> noise(0.0, 2.0);
  const RigidTransform T = random_rigid(rng);
  std::vector<Vec3> p, q;
  for (int i = 0; i < 10; ++i) {
    p.push_back(Vec3(u(rng), u(rng), u(rng)));
    q.push_back(T.apply(p.back()) + Vec3(noise(rng), noise(rng), noise(rng)));
  }
  auto cost = [&](const RigidTransform& X) {
    double s = 0;
    for (std::size_t i = 0; i < p.size(); ++i) s += (X.apply(p[i]) - q[i]).squaredNorm();
    return s;
  };
  const RigidTransform H = horn_rigid(p, q);
  EXPECT_LE(cost(H), cost(T));
  for (int k = 0; k < 50; ++k) {
    RigidTransform X = H;
    const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
    X.R = Eigen::AngleAxisd(1e-3, axis).toRotationMatrix() * H.R;
    X.t += 1e-2 * axis;
    EXPECT_GE(cost(X), cost(H) - 1e-9);
  }
}

TEST(Landmarks, TooFewOrCollinearPointsAreRefused) {
  // Compared: inputs with no unique rotation against a clear InputError.
  const std::vector<Vec3> two{Vec3(0, 0, 0), Vec3(1, 0, 0)};
  EXPECT_THROW(horn_rigid(two, two), InputError);
  const std::vector<Vec3> line{Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2), Vec3(5, 5, 5)};
  EXPECT_THROW(horn_rigid(line, line), InputError);
}

TEST(Landmarks, ErrorsAgainstAKnownTrackerFrameAndDeformation) {
  // Compared: hand-computable errors. The tracker frame is a known rigid motion of the CT frame; the
  // simulation lifts every point 10 mm anteriorly (+y); the "measured" after-points lift 12 mm anteriorly
  // and 1 mm superiorly. Then the alignment is exact (rms 0), every position error is √(2² + 1²) mm, and
  // the per-axis displacement errors are 0 (R–L), 2 (A–P), 1 (S–I) mm.
  std::mt19937 rng(3);
  const RigidTransform ct_to_tracker = random_rigid(rng);
  const std::vector<Vec3> ct{Vec3(0, 0, 0), Vec3(100, 0, 0), Vec3(0, 100, 0), Vec3(0, 0, 100), Vec3(50, 50, 20)};
  std::vector<Landmark> marks;
  for (std::size_t i = 0; i < ct.size(); ++i) {
    Landmark m;
    m.name = "p" + std::to_string(i);
    m.ct_mm = ct[i];
    m.measured_before_mm = ct_to_tracker.apply(ct[i]);
    m.measured_after_mm = ct_to_tracker.apply(ct[i] + Vec3(0, 12, 1));
    marks.push_back(m);
  }
  Landmark unmeasured;
  unmeasured.name = "port";
  unmeasured.ct_mm = Vec3(10, 10, 10);
  marks.push_back(unmeasured);
  const LandmarkEvaluation e = evaluate_landmarks(marks, [](const Vec3& p) -> Vec3 { return p + Vec3(0, 10, 0); });
  ASSERT_TRUE(e.measured);
  EXPECT_NEAR(e.alignment_rms_mm, 0.0, 1e-9);
  EXPECT_NEAR(e.position_error_mm, std::sqrt(5.0), 1e-9);
  EXPECT_NEAR(e.displacement_error_mm[0], 0.0, 1e-9);
  EXPECT_NEAR(e.displacement_error_mm[1], 2.0, 1e-9);
  EXPECT_NEAR(e.displacement_error_mm[2], 1.0, 1e-9);
  EXPECT_EQ((e.points.back().simulated_mm - Vec3(10, 20, 10)).norm(), 0.0);
  EXPECT_FALSE(e.points.back().measured);
  const nlohmann::json j = to_json(e);
  EXPECT_EQ(j.at("points").size(), 6u);
  EXPECT_NEAR(j.at("displacement_error_mm").at("ventrodorsal").get<double>(), 2.0, 1e-9);
}
