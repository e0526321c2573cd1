#include "image/known_intrinsics.h"

#include <cmath>
#include <sstream>

#include "tessera/errors.h"

namespace tessera {
namespace {

std::string FormatKEntry(double value) {
  std::ostringstream stream;
  stream.precision(6);
  stream << value;
  return stream.str();
}

// Refuses focal lengths that are not positive and finite; records an aspect ratio out of
// range.
void CheckFocalLengths(double fx, double fy, const std::string& source, const std::string& fx_name,
                       const std::string& fy_name, CameraSettings* settings) {
  for (const auto& [value, name] : {std::pair{fx, fx_name}, std::pair{fy, fy_name}}) {
    if (!(value > 0) || !std::isfinite(value)) {
      throw InputError(source + ": " + name + " is " + FormatKEntry(value) +
                       ": focal lengths must be positive finite numbers of pixels");
    }
  }
  const double aspect = fy / fx;
  if (aspect < kMinKnownAspectRatio || aspect > kMaxKnownAspectRatio) {
    settings->known_intrinsics_problems.push_back(
        source + ": the aspect ratio fy / fx (" + fy_name + " / " + fx_name + ") is " +
        FormatKEntry(aspect) + ", outside [" + FormatKEntry(kMinKnownAspectRatio) + ", " +
        FormatKEntry(kMaxKnownAspectRatio) + "]: is one of them mistyped?");
  }
}

void CheckFinite(const Eigen::Vector4d& values, const std::string& source) {
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(values(i))) {
      throw InputError(source + ": value " + std::to_string(i + 1) + " (" +
                       FormatKEntry(values(i)) + ") is not a finite number");
    }
  }
}

}  // namespace

void SetKnownIntrinsics(const Eigen::Matrix3d& K, const std::string& source,
                        CameraSettings* settings) {
  settings->known_intrinsics_problems.clear();
  if (K(2, 0) != 0 || K(2, 1) != 0 || K(2, 2) != 1) {
    const bool transposed = K(0, 2) == 0 && K(1, 2) == 0 && K(2, 2) == 1;
    throw InputError(
        source + ": the bottom row K[2] is '" + FormatKEntry(K(2, 0)) + " " +
        FormatKEntry(K(2, 1)) + " " + FormatKEntry(K(2, 2)) +
        "', not '0 0 1': not a calibration matrix" +
        (transposed ? " (it looks transposed: cx and cy belong in the last column)" : ""));
  }
  if (K(1, 0) != 0) {
    throw InputError(source + ": K[1][0] is " + FormatKEntry(K(1, 0)) +
                     ", not 0: not an upper triangular calibration matrix");
  }
  CheckFocalLengths(K(0, 0), K(1, 1), source, "K[0][0] (fx)", "K[1][1] (fy)", settings);
  if (K(0, 1) != 0) {
    settings->known_intrinsics_problems.push_back(
        source + ": K[0][1] (the skew) is " + FormatKEntry(K(0, 1)) +
        ", not 0: Tessera's camera models have no skew, and it would be dropped");
  }
  settings->known_intrinsics = Eigen::Vector4d(K(0, 0), K(1, 1), K(0, 2), K(1, 2));
  CheckFinite(*settings->known_intrinsics, source);
  settings->known_intrinsics_source = source;
}

void SetKnownIntrinsics(const Eigen::Vector4d& fx_fy_cx_cy, const std::string& source,
                        CameraSettings* settings) {
  settings->known_intrinsics_problems.clear();
  CheckFinite(fx_fy_cx_cy, source);
  CheckFocalLengths(fx_fy_cx_cy(0), fx_fy_cx_cy(1), source, "fx", "fy", settings);
  settings->known_intrinsics = fx_fy_cx_cy;
  settings->known_intrinsics_source = source;
}

}  // namespace tessera
