#include "geometry/similarity_transform.h"

#include <Eigen/Dense>

namespace tessera {

Similarity3d EstimateSimilarity(const std::vector<Eigen::Vector3d>& src,
                                const std::vector<Eigen::Vector3d>& dst) {
  const size_t n = src.size();
  Eigen::Vector3d mean_src = Eigen::Vector3d::Zero(), mean_dst = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    mean_src += src[i];
    mean_dst += dst[i];
  }
  mean_src /= n;
  mean_dst /= n;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double variance_src = 0;
  for (size_t i = 0; i < n; ++i) {
    covariance += (dst[i] - mean_dst) * (src[i] - mean_src).transpose();
    variance_src += (src[i] - mean_src).squaredNorm();
  }
  covariance /= n;
  variance_src /= n;

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  // A reflection would fit better when the points are noisy or planar-degenerate; the
  // sign fix keeps a proper rotation.
  Eigen::Vector3d signs = Eigen::Vector3d::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) signs(2) = -1;
  Similarity3d dst_from_src;
  dst_from_src.rotation = svd.matrixU() * signs.asDiagonal() * svd.matrixV().transpose();
  dst_from_src.scale = svd.singularValues().dot(signs) / variance_src;
  dst_from_src.translation = mean_dst - dst_from_src.scale * dst_from_src.rotation * mean_src;
  return dst_from_src;
}

void TransformModel(const Similarity3d& new_from_old, Reconstruction* model) {
  for (auto& [image_id, image] : model->images) {
    const Eigen::Matrix3d cam_from_new =
        image.cam_from_world.rotation.toRotationMatrix() * new_from_old.rotation.transpose();
    image.cam_from_world.translation = new_from_old.scale * image.cam_from_world.translation -
                                       cam_from_new * new_from_old.translation;
    image.cam_from_world.rotation = Eigen::Quaterniond(cam_from_new).normalized();
  }
  for (auto& [point3D_id, point3D] : model->points3D) point3D.xyz = new_from_old * point3D.xyz;
}

}  // namespace tessera
