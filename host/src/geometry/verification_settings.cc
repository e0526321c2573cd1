#include "geometry/verification_settings.h"

namespace tessera {

// A field added to VerificationSettings must be in ToJson too, or verified pairs of
// other settings would be reused: this fails to compile until the size is updated here.
static_assert(sizeof(VerificationSettings) == 48,
              "VerificationSettings changed: add the new field to ToJson, then update this size");

nlohmann::json VerificationSettings::ToJson() const {
  return {{"max_error_px", max_error_px},
          {"confidence", confidence},
          {"min_num_trials", min_num_trials},
          {"max_num_trials", max_num_trials},
          {"min_inlier_ratio", min_inlier_ratio},
          {"min_num_inliers", min_num_inliers},
          {"max_H_inlier_ratio", max_H_inlier_ratio}};
}

void VerificationSettings::Check() const {
  const option_list::Checker check("VerificationSettings");
  VisitVerificationSettings(*this, check);
  check("min_num_trials", min_num_trials, 1, max_num_trials);
}

}  // namespace tessera
