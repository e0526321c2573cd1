#include "geometry/essential_matrix.h"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <limits>

#include "geometry/triangulation.h"

namespace tessera {
namespace {

// Points beyond 1000 baselines carry no depth information (t has unit norm).
constexpr double kMinDepth = std::numeric_limits<double>::epsilon();
constexpr double kMaxDepth = 1000.0;

bool InFrontOfBoth(double depth1, double depth2) {
  return depth1 > kMinDepth && depth1 < kMaxDepth && depth2 > kMinDepth && depth2 < kMaxDepth;
}

// Counts and collects points in front of both cameras for the candidate (R, t),
// triangulating once for both signs of t: with P1 = [I | 0], the DLT solution for
// (R, -t) is exactly the negated solution for (R, t).
void CheckCheiralityBothSigns(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                              const std::vector<Eigen::Vector2d>& points1,
                              const std::vector<Eigen::Vector2d>& points2,
                              std::vector<Eigen::Vector3d>* points3D_pos,
                              std::vector<Eigen::Vector3d>* points3D_neg) {
  const Eigen::Matrix<double, 3, 4> cam1_from_world = Eigen::Matrix<double, 3, 4>::Identity();
  Eigen::Matrix<double, 3, 4> cam2_from_world;
  cam2_from_world.leftCols<3>() = R;
  cam2_from_world.col(3) = t;
  points3D_pos->clear();
  points3D_neg->clear();
  const Eigen::Vector3d R_row2 = R.row(2).transpose();
  for (size_t i = 0; i < points1.size(); ++i) {
    const Eigen::Vector3d point3D =
        TriangulatePoint(cam1_from_world, cam2_from_world, points1[i], points2[i]);
    // Depth in camera 1 is z; in camera 2 it is R.row(2) X + t_z (R orthonormal).
    const double depth1 = point3D.z();
    const double depth2_pos = R_row2.dot(point3D) + t.z();
    const double depth2_neg = -R_row2.dot(point3D) - t.z();
    if (InFrontOfBoth(depth1, depth2_pos)) points3D_pos->push_back(point3D);
    if (InFrontOfBoth(-depth1, depth2_neg)) points3D_neg->push_back(-point3D);
  }
}

// Counts the correspondences in front of both cameras for the candidate (R, t) and for
// (R, -t). With f1 = (x1, 1) and f2 = (x2, 1), the depths d1, d2 minimise
// |d2 f2 - d1 R f1 - t|^2 (both z depths, as the rays have z = 1); negating t negates
// both. Parallel rays (no unique minimum) count for neither.
void CountInFrontBothSigns(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                           const std::vector<Eigen::Vector2d>& points1,
                           const std::vector<Eigen::Vector2d>& points2, size_t* num_pos,
                           size_t* num_neg) {
  *num_pos = 0;
  *num_neg = 0;
  for (size_t i = 0; i < points1.size(); ++i) {
    const Eigen::Vector3d a = R * points1[i].homogeneous();
    const Eigen::Vector3d b = points2[i].homogeneous();
    const double aa = a.squaredNorm(), bb = b.squaredNorm(), ab = a.dot(b);
    const double at = a.dot(t), bt = b.dot(t);
    const double det = aa * bb - ab * ab;
    if (!(det > 0)) continue;
    const double depth1 = (ab * bt - bb * at) / det;
    const double depth2 = (aa * bt - ab * at) / det;
    if (InFrontOfBoth(depth1, depth2)) ++*num_pos;
    if (InFrontOfBoth(-depth1, -depth2)) ++*num_neg;
  }
}

}  // namespace

void DecomposeEssentialMatrix(const Eigen::Matrix3d& E, Eigen::Matrix3d* R1, Eigen::Matrix3d* R2,
                              Eigen::Vector3d* t) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(E, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  Eigen::Matrix3d Vt = svd.matrixV().transpose();
  // Proper rotations only; E is defined up to sign, so flipping U or V is harmless.
  if (U.determinant() < 0) U *= -1;
  if (Vt.determinant() < 0) Vt *= -1;
  Eigen::Matrix3d W;
  W << 0, 1, 0, -1, 0, 0, 0, 0, 1;
  *R1 = U * W * Vt;
  *R2 = U * W.transpose() * Vt;
  *t = U.col(2).normalized();
}

bool PoseFromEssentialMatrix(const Eigen::Matrix3d& E, const std::vector<Eigen::Vector2d>& points1,
                             const std::vector<Eigen::Vector2d>& points2, Rigid3d* cam2_from_cam1,
                             std::vector<Eigen::Vector3d>* points3D) {
  Eigen::Matrix3d R1, R2;
  Eigen::Vector3d t;
  DecomposeEssentialMatrix(E, &R1, &R2, &t);

  std::vector<Eigen::Vector3d> points_pos, points_neg;
  points3D->clear();
  for (const Eigen::Matrix3d* R : {&R1, &R2}) {
    CheckCheiralityBothSigns(*R, t, points1, points2, &points_pos, &points_neg);
    for (const bool positive : {true, false}) {
      std::vector<Eigen::Vector3d>& candidate = positive ? points_pos : points_neg;
      if (candidate.size() > points3D->size()) {
        cam2_from_cam1->rotation = Eigen::Quaterniond(*R).normalized();
        cam2_from_cam1->translation = positive ? t : Eigen::Vector3d(-t);
        points3D->swap(candidate);
      }
    }
  }
  return !points3D->empty();
}

size_t RelativePoseFromEssentialMatrix(const Eigen::Matrix3d& E,
                                       const std::vector<Eigen::Vector2d>& points1,
                                       const std::vector<Eigen::Vector2d>& points2,
                                       Rigid3d* cam2_from_cam1) {
  Eigen::Matrix3d R1, R2;
  Eigen::Vector3d t;
  DecomposeEssentialMatrix(E, &R1, &R2, &t);
  size_t best = 0;
  for (const Eigen::Matrix3d* R : {&R1, &R2}) {
    size_t num_pos = 0, num_neg = 0;
    CountInFrontBothSigns(*R, t, points1, points2, &num_pos, &num_neg);
    for (const bool positive : {true, false}) {
      const size_t count = positive ? num_pos : num_neg;
      if (count > best) {
        cam2_from_cam1->rotation = Eigen::Quaterniond(*R).normalized();
        cam2_from_cam1->translation = positive ? t : Eigen::Vector3d(-t);
        best = count;
      }
    }
  }
  return best;
}

Eigen::Matrix3d EssentialMatrixFromPose(const Rigid3d& cam2_from_cam1) {
  const Eigen::Vector3d& t = cam2_from_cam1.translation;
  Eigen::Matrix3d t_cross;
  t_cross << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  return t_cross * cam2_from_cam1.rotation.toRotationMatrix();
}

Eigen::Matrix3d FundamentalFromEssentialMatrix(const Eigen::Matrix3d& K2, const Eigen::Matrix3d& E,
                                               const Eigen::Matrix3d& K1) {
  return K2.transpose().inverse() * E * K1.inverse();
}

}  // namespace tessera
