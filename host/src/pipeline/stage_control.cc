#include "pipeline/stage_control.h"

namespace tessera {

const char* StageStatusName(StageStatus status) {
  switch (status) {
    case StageStatus::kCompleted:
      return "completed";
    case StageStatus::kCancelled:
      return "cancelled";
  }
  return "unknown";
}

}  // namespace tessera
