// The robust estimators on numpy (tessera._estimate_absolute_pose, _estimate_essential_matrix,
// _estimate_fundamental_matrix, _estimate_homography_matrix): Tessera's own LO-RANSAC and
// minimal solvers, as the mapper and the verification use them, each returning pycolmap's
// fields and an inlier mask; and the verification itself (_estimate_two_view_geometry).
// The Python layer (tessera/_estimators.py) reads pycolmap's option dicts and passes the
// RANSAC fields here as one dict of known keys.

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "estimators/absolute_pose.h"
#include "estimators/essential_matrix.h"
#include "estimators/fundamental_matrix.h"
#include "estimators/homography_matrix.h"
#include "estimators/ransac.h"
#include "geometry/two_view_geometry_estimation.h"
#include "geometry/verification_settings.h"
#include "tessera/camera.h"
#include "tessera/errors.h"
#include "tessera/sfm/incremental_mapper.h"
#include "tessera/sfm/incremental_mapper_options.h"
#include "two_view_geometry_dict.h"

namespace py = pybind11;

namespace tessera::python {
namespace {

using DoubleRows = py::array_t<double, py::array::c_style | py::array::forcecast>;

// `value` as N rows of `Cols` finite numbers: TypeError naming the argument for what is no
// (N, Cols) array of numbers, InputError naming the row of a value that is not finite.
template <int Cols>
std::vector<Eigen::Matrix<double, Cols, 1>> Rows(const py::object& value, const char* function,
                                                 const char* name) {
  const std::string shape = "(N, " + std::to_string(Cols) + ")";
  // (A default array_t is an empty array, not a null one: hence the flag.)
  const bool numbers = !value.is_none() && !py::isinstance<py::str>(value);
  const DoubleRows rows = numbers ? DoubleRows::ensure(value) : DoubleRows();
  if (numbers && !rows) PyErr_Clear();  // numpy could not convert it
  if (!numbers || !rows) {
    throw py::type_error(std::string(function) + ": " + name + " must be an " + shape +
                         " array of numbers, not " +
                         py::str(py::type::of(value).attr("__name__")).cast<std::string>());
  }
  if (rows.ndim() != 2 || rows.shape(1) != Cols) {
    throw py::type_error(std::string(function) + ": " + name + " must have shape " + shape +
                         ", not " + py::str(py::tuple(rows.attr("shape"))).cast<std::string>());
  }
  const auto view = rows.template unchecked<2>();
  std::vector<Eigen::Matrix<double, Cols, 1>> points(static_cast<size_t>(rows.shape(0)));
  for (size_t i = 0; i < points.size(); ++i) {
    for (int j = 0; j < Cols; ++j) points[i](j) = view(static_cast<py::ssize_t>(i), j);
    if (!points[i].allFinite()) {
      throw InputError(std::string(function) + ": " + name + " row " + std::to_string(i) +
                       " holds a value that is not finite");
    }
  }
  return points;
}

// Both arguments have one row per correspondence, at least `min_num` of them.
void CheckCounts(const char* function, const char* name1, size_t n1, const char* name2, size_t n2,
                 int min_num) {
  if (n1 != n2) {
    throw InputError(std::string(function) + ": " + name1 + " has " + std::to_string(n1) +
                     " rows but " + name2 + " has " + std::to_string(n2) +
                     " (one row each per correspondence)");
  }
  if (n1 < static_cast<size_t>(min_num)) {
    throw InputError(std::string(function) + ": needs at least " + std::to_string(min_num) +
                     " correspondences, got " + std::to_string(n1));
  }
}

void CheckCamera(const char* function, const char* name, const Camera& camera) {
  if (!camera.IsValid() || !(camera.MeanFocalLength() > 0)) {
    throw InputError(std::string(function) + ": " + name + " (camera " +
                     std::to_string(camera.camera_id) +
                     ") is not a valid camera: its model, parameter count, size or focal length");
  }
}

// The RANSAC fields of the dict the Python layer built (every key present), checked as
// the host checks them (InputError naming the field); max_error in pixels.
RANSACOptions RansacOptions(const py::dict& ransac, double max_error) {
  RANSACOptions options;
  options.max_error = max_error;
  options.min_inlier_ratio = ransac["min_inlier_ratio"].cast<double>();
  options.confidence = ransac["confidence"].cast<double>();
  options.dyn_num_trials_multiplier = ransac["dyn_num_trials_multiplier"].cast<double>();
  options.min_num_trials = ransac["min_num_trials"].cast<int>();
  options.max_num_trials = ransac["max_num_trials"].cast<int>();
  options.Check();
  return options;
}

uint64_t Seed(const py::dict& ransac) { return ransac["random_seed"].cast<uint64_t>(); }

double MaxErrorPx(const py::dict& ransac) { return ransac["max_error"].cast<double>(); }

template <typename Estimator, typename LocalEstimator>
RANSACReport<typename Estimator::M_t> RunLORANSAC(const RANSACOptions& options, uint64_t seed,
                                                  const std::vector<typename Estimator::X_t>& X,
                                                  const std::vector<typename Estimator::Y_t>& Y) {
  const LORANSAC<Estimator, LocalEstimator> ransac(options, seed);  // checks before the release
  const py::gil_scoped_release release;
  return ransac.Estimate(X, Y);
}

py::array_t<bool> InlierMask(const std::vector<char>& mask) {
  py::array_t<bool> array(static_cast<py::ssize_t>(mask.size()));
  auto out = array.mutable_unchecked<1>();
  for (size_t i = 0; i < mask.size(); ++i) out(static_cast<py::ssize_t>(i)) = mask[i] != 0;
  return array;
}

// pycolmap's result of a matrix estimator: {name: the 3x3 model, num_inliers, inlier_mask},
// or None when no model has kMinNumSamples inliers.
py::object MatrixResult(const char* name, const RANSACReport<Eigen::Matrix3d>& report) {
  if (!report.success) return py::none();
  py::dict result;
  result[name] = report.model;
  result["num_inliers"] = report.support.num_inliers;
  result["inlier_mask"] = InlierMask(report.inlier_mask);
  return result;
}

py::object EstimateAbsolutePose(const py::object& points2D_in, const py::object& points3D_in,
                                const Camera& camera, const py::dict& ransac, bool refine) {
  const char* function = "estimate_absolute_pose";
  const auto points2D = Rows<2>(points2D_in, function, "points2D");
  const auto points3D = Rows<3>(points3D_in, function, "points3D");
  CheckCounts(function, "points2D", points2D.size(), "points3D", points3D.size(),
              P3PEstimator::kMinNumSamples);
  CheckCamera(function, "camera", camera);
  // As the mapper registers an image: normalised points, the pixel threshold through the
  // mean focal length.
  std::vector<Eigen::Vector2d> normalized(points2D.size());
  for (size_t i = 0; i < points2D.size(); ++i) {
    normalized[i] = camera.CamFromImg(points2D[i]);
    if (!normalized[i].allFinite()) {
      throw InputError(std::string(function) + ": points2D row " + std::to_string(i) +
                       " has no finite normalised coordinates in the camera");
    }
  }
  const RANSACOptions options =
      RansacOptions(ransac, camera.CamFromImgThreshold(MaxErrorPx(ransac)));
  const auto report =
      RunLORANSAC<P3PEstimator, EPnPEstimator>(options, Seed(ransac), normalized, points3D);
  if (!report.success) return py::none();
  Eigen::Matrix<double, 3, 4> cam_from_world = report.model;
  if (refine) {
    std::vector<Eigen::Vector2d> inliers2D;
    std::vector<Eigen::Vector3d> inliers3D;
    for (size_t i = 0; i < normalized.size(); ++i) {
      if (!report.inlier_mask[i]) continue;
      inliers2D.push_back(normalized[i]);
      inliers3D.push_back(points3D[i]);
    }
    const py::gil_scoped_release release;
    RefineAbsolutePose(inliers2D, inliers3D, &cam_from_world);
  }
  const Eigen::Quaterniond rotation =
      Eigen::Quaterniond(Eigen::Matrix3d(cam_from_world.leftCols<3>())).normalized();
  const Eigen::Vector3d translation = cam_from_world.col(3);
  py::dict result;
  result["cam_from_world"] =
      py::module_::import("tessera._geometry")
          .attr("Rigid3d")(py::make_tuple(rotation.x(), rotation.y(), rotation.z(), rotation.w()),
                           translation);
  result["num_inliers"] = report.support.num_inliers;
  result["inlier_mask"] = InlierMask(report.inlier_mask);
  return result;
}

py::object EstimateEssentialMatrix(const py::object& points1_in, const py::object& points2_in,
                                   const Camera& camera1, const Camera& camera2,
                                   const py::dict& ransac) {
  const char* function = "estimate_essential_matrix";
  const auto points1 = Rows<2>(points1_in, function, "points1");
  const auto points2 = Rows<2>(points2_in, function, "points2");
  CheckCounts(function, "points1", points1.size(), "points2", points2.size(),
              EssentialMatrixFivePointEstimator::kMinNumSamples);
  CheckCamera(function, "camera1", camera1);
  CheckCamera(function, "camera2", camera2);
  std::vector<Eigen::Vector2d> normalized1(points1.size()), normalized2(points2.size());
  for (size_t i = 0; i < points1.size(); ++i) {
    normalized1[i] = camera1.CamFromImg(points1[i]);
    normalized2[i] = camera2.CamFromImg(points2[i]);
    if (!normalized1[i].allFinite() || !normalized2[i].allFinite()) {
      throw InputError(std::string(function) + ": row " + std::to_string(i) +
                       " has no finite normalised coordinates in its camera");
    }
  }
  // The pixel threshold through each camera, averaged, as the verification does.
  const double max_error_px = MaxErrorPx(ransac);
  const RANSACOptions options = RansacOptions(
      ransac,
      (camera1.CamFromImgThreshold(max_error_px) + camera2.CamFromImgThreshold(max_error_px)) / 2);
  return MatrixResult(
      "E", RunLORANSAC<EssentialMatrixFivePointEstimator, EssentialMatrixFivePointEstimator>(
               options, Seed(ransac), normalized1, normalized2));
}

// F and H: on pixels, the threshold as given.
template <typename Estimator, typename LocalEstimator>
py::object EstimatePixelMatrix(const char* function, const char* name, const py::object& points1_in,
                               const py::object& points2_in, const py::dict& ransac) {
  const auto points1 = Rows<2>(points1_in, function, "points1");
  const auto points2 = Rows<2>(points2_in, function, "points2");
  CheckCounts(function, "points1", points1.size(), "points2", points2.size(),
              LocalEstimator::kMinNumSamples);
  const RANSACOptions options = RansacOptions(ransac, MaxErrorPx(ransac));
  return MatrixResult(
      name, RunLORANSAC<Estimator, LocalEstimator>(options, Seed(ransac), points1, points2));
}

// Keypoints at `points` (no shape: identity frames), for the verification.
FeatureKeypoints Keypoints(const std::vector<Eigen::Vector2d>& points) {
  FeatureKeypoints keypoints;
  keypoints.reserve(points.size());
  for (const Eigen::Vector2d& point : points) {
    keypoints.emplace_back(static_cast<float>(point.x()), static_cast<float>(point.y()));
  }
  return keypoints;
}

// (K, 2) indices into points1 and points2, or row i to row i where `value` is None.
FeatureMatches Matches(const py::object& value, size_t n1, size_t n2) {
  const char* function = "estimate_two_view_geometry";
  FeatureMatches matches;
  if (value.is_none()) {
    if (n1 != n2) {
      throw InputError(std::string(function) + ": points1 has " + std::to_string(n1) +
                       " rows but points2 has " + std::to_string(n2) +
                       "; without matches, row i of one matches row i of the other");
    }
    for (size_t i = 0; i < n1; ++i) {
      matches.push_back({static_cast<point2D_t>(i), static_cast<point2D_t>(i)});
    }
    return matches;
  }
  using IndexRows = py::array_t<int64_t, py::array::c_style | py::array::forcecast>;
  const bool is_array = py::isinstance<py::array>(value) || py::isinstance<py::list>(value) ||
                        py::isinstance<py::tuple>(value);
  const IndexRows rows = is_array ? IndexRows::ensure(value) : IndexRows();
  if (is_array && !rows) PyErr_Clear();
  if (!is_array || !rows || rows.ndim() != 2 || rows.shape(1) != 2) {
    throw py::type_error(std::string(function) +
                         ": matches must be None or a (K, 2) array of indices into points1 "
                         "and points2");
  }
  const auto view = rows.unchecked<2>();
  for (py::ssize_t k = 0; k < rows.shape(0); ++k) {
    const int64_t idx1 = view(k, 0), idx2 = view(k, 1);
    if (idx1 < 0 || static_cast<size_t>(idx1) >= n1 || idx2 < 0 ||
        static_cast<size_t>(idx2) >= n2) {
      throw InputError(std::string(function) + ": matches row " + std::to_string(k) + " (" +
                       std::to_string(idx1) + ", " + std::to_string(idx2) +
                       ") is not a pair of indices into points1 (" + std::to_string(n1) +
                       " rows) and points2 (" + std::to_string(n2) + " rows)");
    }
    matches.push_back({static_cast<point2D_t>(idx1), static_cast<point2D_t>(idx2)});
  }
  return matches;
}

py::dict EstimateTwoView(const Camera& camera1, const py::object& points1_in, const Camera& camera2,
                         const py::object& points2_in, const py::object& matches_in,
                         const py::dict& options) {
  const char* function = "estimate_two_view_geometry";
  const auto points1 = Rows<2>(points1_in, function, "points1");
  const auto points2 = Rows<2>(points2_in, function, "points2");
  CheckCamera(function, "camera1", camera1);
  CheckCamera(function, "camera2", camera2);
  const FeatureMatches matches = Matches(matches_in, points1.size(), points2.size());
  VerificationSettings settings;
  settings.max_error_px = MaxErrorPx(options);
  settings.confidence = options["confidence"].cast<double>();
  settings.min_num_trials = options["min_num_trials"].cast<int>();
  settings.max_num_trials = options["max_num_trials"].cast<int>();
  settings.min_inlier_ratio = options["min_inlier_ratio"].cast<double>();
  settings.min_num_inliers = options["min_num_inliers"].cast<int>();
  settings.max_H_inlier_ratio = options["max_H_inlier_ratio"].cast<double>();
  RANSACOptions checked;  // the fields the verification's RANSAC takes, checked before it runs
  checked.max_error = settings.max_error_px;
  checked.confidence = settings.confidence;
  checked.min_num_trials = settings.min_num_trials;
  checked.max_num_trials = settings.max_num_trials;
  checked.min_inlier_ratio = settings.min_inlier_ratio;
  checked.Check();
  if (!(settings.max_H_inlier_ratio >= 0 && settings.max_H_inlier_ratio <= 1)) {
    throw InputError(std::string(function) + ": max_H_inlier_ratio = " +
                     std::to_string(settings.max_H_inlier_ratio) + " is not in [0, 1]");
  }
  const FeatureKeypoints keypoints1 = Keypoints(points1), keypoints2 = Keypoints(points2);
  TwoViewGeometry geometry;
  {
    const py::gil_scoped_release release;
    geometry = EstimateTwoViewGeometry(camera1, keypoints1, camera2, keypoints2, matches, settings,
                                       Seed(options));
  }
  return TwoViewGeometryDict(std::move(geometry), function);
}

// The defaults of the estimators' options, read from their owners so that they are stated
// once: the pipeline's verification (VerificationSettings: the two-view matrices and
// geometry), the mapper's registration (IncrementalMapperOptions' abs_pose_max_error,
// MapperRansacOptions' abs_pose_confidence) and RANSACOptions' dyn_num_trials_multiplier.
py::dict EstimatorDefaults() {
  const VerificationSettings verification;
  py::dict two_view;
  two_view["max_error"] = verification.max_error_px;
  two_view["min_inlier_ratio"] = verification.min_inlier_ratio;
  two_view["confidence"] = verification.confidence;
  two_view["dyn_num_trials_multiplier"] = RANSACOptions().dyn_num_trials_multiplier;
  two_view["min_num_trials"] = verification.min_num_trials;
  two_view["max_num_trials"] = verification.max_num_trials;
  py::dict geometry;
  geometry["min_num_inliers"] = verification.min_num_inliers;
  geometry["max_H_inlier_ratio"] = verification.max_H_inlier_ratio;
  py::dict absolute_pose;
  absolute_pose["max_error"] = IncrementalMapperOptions().abs_pose_max_error;
  absolute_pose["confidence"] = MapperRansacOptions().abs_pose_confidence;
  absolute_pose["dyn_num_trials_multiplier"] = RANSACOptions().dyn_num_trials_multiplier;
  py::dict defaults;
  defaults["two_view"] = two_view;
  defaults["two_view_geometry"] = geometry;
  defaults["absolute_pose"] = absolute_pose;
  return defaults;
}

}  // namespace

void BindEstimators(py::module_& module) {
  module.def("_estimator_defaults", &EstimatorDefaults,
             "The option defaults that tessera/_estimators.py reads from their owners");
  module.def("_estimate_absolute_pose", &EstimateAbsolutePose, py::arg("points2D"),
             py::arg("points3D"), py::arg("camera"), py::arg("ransac"), py::arg("refine"),
             "P3P + EPnP LO-RANSAC on normalised points, then RefineAbsolutePose on the "
             "inliers; use tessera.estimate_absolute_pose");
  module.def("_estimate_essential_matrix", &EstimateEssentialMatrix, py::arg("points1"),
             py::arg("points2"), py::arg("camera1"), py::arg("camera2"), py::arg("ransac"),
             "Five-point LO-RANSAC on normalised points; use tessera.estimate_essential_matrix");
  module.def(
      "_estimate_fundamental_matrix",
      [](const py::object& points1, const py::object& points2, const py::dict& ransac) {
        return EstimatePixelMatrix<FundamentalMatrixSevenPointEstimator,
                                   FundamentalMatrixEightPointEstimator>(
            "estimate_fundamental_matrix", "F", points1, points2, ransac);
      },
      py::arg("points1"), py::arg("points2"), py::arg("ransac"),
      "Seven-point LO-RANSAC (eight-point local fits) on pixels; use "
      "tessera.estimate_fundamental_matrix");
  module.def(
      "_estimate_homography_matrix",
      [](const py::object& points1, const py::object& points2, const py::dict& ransac) {
        return EstimatePixelMatrix<HomographyMatrixEstimator, HomographyMatrixEstimator>(
            "estimate_homography_matrix", "H", points1, points2, ransac);
      },
      py::arg("points1"), py::arg("points2"), py::arg("ransac"),
      "Four-point DLT LO-RANSAC on pixels; use tessera.estimate_homography_matrix");
  module.def("_estimate_two_view_geometry", &EstimateTwoView, py::arg("camera1"),
             py::arg("points1"), py::arg("camera2"), py::arg("points2"), py::arg("matches"),
             py::arg("options"),
             "The pipeline's geometric verification (EstimateTwoViewGeometry) on numpy; use "
             "tessera.estimate_two_view_geometry");
}

}  // namespace tessera::python
