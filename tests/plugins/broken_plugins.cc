// Deliberately broken plugins, one per way the loader must refuse a plugin, and one
// plugin of every kind that fails on request (throws every kind of exception, crashes,
// aborts or ends the process). Each is compiled into its own folder with one
// TESSERA_TEST_CASE_* macro defined; see tests/CMakeLists.txt.

#include <algorithm>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <memory>
#include <stdexcept>

#include "tessera/sdk.h"

namespace {

class TestPairSelector : public tessera::PairSelector {
 public:
  explicit TestPairSelector(const nlohmann::json& options) {
    tessera::OptionReader reader(options);
    reader.Get<int>("overlap", 3, 1, 100);
    reader.Finish();
    effective_options_ = reader.Effective();
#ifdef TESSERA_TEST_CASE_FACTORY_THROWS
    throw std::runtime_error("cannot reach the license server");
#endif
  }
  std::vector<tessera::ImageIndexPair> SelectPairs(
      const tessera::PairSelectionInput& input) const override {
    std::vector<tessera::ImageIndexPair> pairs;
    for (size_t i = 0; i + 1 < input.images.size(); ++i) pairs.emplace_back(i, i + 1);
    return pairs;
  }
};

// An exception type that only this plugin knows.
class LicenseError : public std::exception {
 public:
  const char* what() const noexcept override { return "the license has expired"; }
};

// Not derived from std::exception at all.
struct NotAnException {
  int code = 7;
};

[[maybe_unused]] void Crash() {
  volatile uintptr_t address = 16;  // not null: sanitizers let the store through
  *reinterpret_cast<volatile int*>(address) = 1;
}

// A block allocated and dropped: a leak for LeakSanitizer to report at exit, naming this
// frame (the sanitizer run's check that leak detection is on and reaches into plugins).
void* volatile g_leak_sink = nullptr;
[[maybe_unused, gnu::noinline]] void LeakOnPurpose() {
  g_leak_sink = std::malloc(4096);
  g_leak_sink = nullptr;
}

// Options shared by the failing plugins: "fail" says how (none, input_error,
// option_error, runtime_error, custom, non_std, segv, abort, exit: exit(0), quick_exit:
// quick_exit(0); leak: 4 KiB allocated and dropped; bad_indices: a matcher returns a
// match beyond the keypoints; bad_result: a mapper returns a model with an image renamed)
// and "in" where (call: the kind's main method; factory: the constructor). A detector
// fails only on images "on_width" pixels wide when that is not 0.
struct Failure {
  std::string how;
  std::string where;
  int on_width = 0;

  explicit Failure(tessera::OptionReader* reader)
      : how(reader->GetString(
            "fail", "none",
            {"none", "input_error", "option_error", "runtime_error", "custom", "non_std", "segv",
             "abort", "exit", "quick_exit", "leak", "bad_indices", "bad_result"})),
        where(reader->GetString("in", "call", {"call", "factory"})),
        on_width(reader->Get<int>("on_width", 0, 0, 100000)) {}

  void Trigger(const std::string& at) const {
    if (at != where) return;
    if (how == "input_error") throw tessera::InputError("this input is not acceptable");
    if (how == "option_error") throw tessera::OptionError("threshold", "must be positive");
    if (how == "runtime_error") throw std::runtime_error("out of detector memory");
    if (how == "custom") throw LicenseError();
    if (how == "non_std") throw NotAnException();
    if (how == "segv") Crash();
    if (how == "abort") std::abort();
    if (how == "exit") std::exit(0);
    if (how == "quick_exit") std::quick_exit(0);
    if (how == "leak") LeakOnPurpose();
  }
};

[[maybe_unused]] Failure ReadFailure(const nlohmann::json& options, nlohmann::json* effective) {
  tessera::OptionReader reader(options);
  Failure failure(&reader);
  reader.Finish();
  *effective = reader.Effective();
  failure.Trigger("factory");
  return failure;
}

// Besides the shared options: "wrap" ({"plugin": NAME, "options": {...}}) detects with
// that detector, made by the host, instead of the grid below, so that a run with it
// registers images; "only_if_env" (a variable name) fails only while that variable is
// set, so that a test can "fix" the plugin without changing its options (which would
// make every image's features stale).
class FailingDetector : public tessera::Detector {
 public:
  explicit FailingDetector(const nlohmann::json& options) : reader_(options), failure_(&reader_) {
    const nlohmann::json wrap = reader_.GetJson("wrap", nullptr);
    only_if_env_ = reader_.GetString("only_if_env", "");
    reader_.Finish();
    effective_options_ = reader_.Effective();
    failure_.Trigger("factory");
    if (wrap.is_object()) {
      wrapped_ = host().Create<tessera::Detector>("detector", wrap.value("plugin", ""),
                                                  wrap.value("options", nlohmann::json::object()));
    }
  }
  // Keypoints on a 4x4 grid, each described by the 16 pixels of its neighbourhood.
  tessera::FeatureSet Detect(const tessera::ImageView& image) const override {
    const bool armed = only_if_env_.empty() || std::getenv(only_if_env_.c_str()) != nullptr;
    if (armed && (failure_.on_width == 0 || failure_.on_width == image.width)) {
      failure_.Trigger("call");
    }
    if (wrapped_) return wrapped_->Detect(image);
    tessera::FeatureSet features;
    if (image.width < 8 || image.height < 8) return features;
    features.descriptors.data.resize(16, 16);
    for (int k = 0; k < 16; ++k) {
      const int x = (k % 4 + 1) * image.width / 5, y = (k / 4 + 1) * image.height / 5;
      features.keypoints.emplace_back(x + 0.5f, y + 0.5f);
      for (int d = 0; d < 16; ++d) {
        const int px = std::min(image.width - 1, x + d % 4),
                  py = std::min(image.height - 1, y + d / 4);
        features.descriptors.data(k, d) = image.data[py * image.stride + px];
      }
    }
    return features;
  }
  tessera::DescriptorMetric Metric() const override {
    return wrapped_ ? wrapped_->Metric() : tessera::DescriptorMetric::kL2;
  }

 private:
  tessera::OptionReader reader_;
  Failure failure_;
  std::string only_if_env_;
  std::unique_ptr<tessera::Detector> wrapped_;
};

class FailingMatcher : public tessera::Matcher {
 public:
  explicit FailingMatcher(const nlohmann::json& options)
      : failure_(ReadFailure(options, &effective_options_)) {}
  tessera::FeatureMatches Match(const tessera::FeatureDescriptors& descriptors1,
                                const tessera::FeatureDescriptors& descriptors2) const override {
    failure_.Trigger("call");
    tessera::FeatureMatches matches;
    for (Eigen::Index i = 0; i < std::min(descriptors1.size(), descriptors2.size()); ++i) {
      matches.push_back({static_cast<tessera::point2D_t>(i), static_cast<tessera::point2D_t>(i)});
    }
    if (failure_.how == "bad_indices") {
      matches.push_back({0, static_cast<tessera::point2D_t>(descriptors2.size() + 7)});
    }
    return matches;
  }

 private:
  Failure failure_;
};

class FailingPairSelector : public tessera::PairSelector {
 public:
  explicit FailingPairSelector(const nlohmann::json& options)
      : failure_(ReadFailure(options, &effective_options_)) {}
  std::vector<tessera::ImageIndexPair> SelectPairs(
      const tessera::PairSelectionInput& input) const override {
    failure_.Trigger("call");
    std::vector<tessera::ImageIndexPair> pairs;
    for (size_t i = 0; i + 1 < input.images.size(); ++i) pairs.emplace_back(i, i + 1);
    return pairs;
  }

 private:
  Failure failure_;
};

class FailingBundleAdjuster : public tessera::BundleAdjuster {
 public:
  explicit FailingBundleAdjuster(const nlohmann::json& options)
      : failure_(ReadFailure(options, &effective_options_)) {}
  tessera::BundleAdjustmentSummary Adjust(const tessera::BundleAdjustmentConfig&,
                                          tessera::Reconstruction*) const override {
    failure_.Trigger("call");
    tessera::BundleAdjustmentSummary summary;
    summary.usable = true;
    return summary;
  }

 private:
  Failure failure_;
};

// Maps nothing (every image left out, with why), or fails on request; "bad_result"
// returns a model holding an image renamed outside the image folder.
class FailingMapper : public tessera::Mapper {
 public:
  explicit FailingMapper(const nlohmann::json& options)
      : failure_(ReadFailure(options, &effective_options_)) {}
  tessera::MapperResult Map(const tessera::MapperInput& input,
                            const tessera::MapperContext&) const override {
    failure_.Trigger("call");
    tessera::MapperResult result;
    if (failure_.how == "bad_result" && !input.images.empty()) {
      tessera::Reconstruction model;
      tessera::Image image = input.images.begin()->second;
      image.name = "../outside.jpg";
      image.registered = true;
      model.cameras[image.camera_id] = input.cameras.at(image.camera_id);
      model.images[image.image_id] = image;
      result.models.push_back(model);
      result.self_checks.resize(1);
      return result;
    }
    for (const auto& [image_id, image] : input.images) {
      result.unregistered_reasons[image_id] = "failing_mapper maps nothing";
    }
    return result;
  }

 private:
  Failure failure_;
};

class FailingExporter : public tessera::Exporter {
 public:
  explicit FailingExporter(const nlohmann::json& options)
      : failure_(ReadFailure(options, &effective_options_)) {}
  void Export(const tessera::Reconstruction&, const tessera::ExportContext&) const override {
    failure_.Trigger("call");
  }

 private:
  Failure failure_;
};

}  // namespace

#if defined(TESSERA_TEST_CASE_FAILING_DETECTOR)
TESSERA_PLUGIN(detector, FailingDetector, "failing_detector", "1.0.0", "Fails on request")
#elif defined(TESSERA_TEST_CASE_FAILING_MATCHER)
TESSERA_PLUGIN(matcher, FailingMatcher, "failing_matcher", "1.0.0", "Fails on request")
#elif defined(TESSERA_TEST_CASE_FAILING_PAIR_SELECTOR)
TESSERA_PLUGIN(pair_selector, FailingPairSelector, "failing_pair_selector", "1.0.0",
               "Fails on request")
#elif defined(TESSERA_TEST_CASE_FAILING_BUNDLE_ADJUSTER)
TESSERA_PLUGIN(bundle_adjuster, FailingBundleAdjuster, "failing_bundle_adjuster", "1.0.0",
               "Fails on request")
#elif defined(TESSERA_TEST_CASE_FAILING_MAPPER)
TESSERA_PLUGIN(mapper, FailingMapper, "failing_mapper", "1.0.0", "Fails on request")
#elif defined(TESSERA_TEST_CASE_FAILING_EXPORTER)
TESSERA_PLUGIN(exporter, FailingExporter, "failing_exporter", "1.0.0", "Fails on request")

#elif defined(TESSERA_TEST_CASE_CRASH_ON_LOAD)
// A static initialiser that crashes as soon as the library is opened.
[[maybe_unused]] static const int crash_on_load = [] {
  Crash();
  return 0;
}();
TESSERA_PLUGIN(pair_selector, TestPairSelector, "crash_on_load", "1.0.0", "Crashes when loaded")

#elif defined(TESSERA_TEST_CASE_TERM_ON_LOAD)
// A static initialiser ended by SIGTERM, as a probe child that an interrupt reaches is: the
// probe must not call that a crash of the plugin.
[[maybe_unused]] static const int term_on_load = [] {
  std::raise(SIGTERM);
  return 0;
}();
TESSERA_PLUGIN(pair_selector, TestPairSelector, "term_on_load", "1.0.0", "Ended by SIGTERM")

#elif defined(TESSERA_TEST_CASE_NO_INFO)
// Exports a function, but no info record.
extern "C" __attribute__((visibility("default"))) int tessera_unrelated_symbol() { return 42; }

#elif defined(TESSERA_TEST_CASE_WRONG_ABI)
extern "C" {
// Its build record is empty: a host reads nothing past abi_version of another version.
const TesseraPluginInfo wrong_abi_info = {999,     "pair_selector",   "future",
                                          "9.0.0", "From the future", TesseraBuildRecord{}};
}
static std::unique_ptr<tessera::Plugin> wrong_abi_create(const nlohmann::json& options) {
  return std::make_unique<TestPairSelector>(options);
}
BOOST_DLL_ALIAS(wrong_abi_info, tessera_plugin_info)
BOOST_DLL_ALIAS(wrong_abi_create, tessera_plugin_create)

#elif defined(TESSERA_TEST_CASE_ABI_ONE)
// A plugin built against ABI 1 (pair selectors saw only file names): its record says 1.
extern "C" {
const TesseraPluginInfo abi_one_info = {1,       "pair_selector",       "names_only",
                                        "1.0.0", "Built against ABI 1", TesseraBuildRecord{}};
}
static std::unique_ptr<tessera::Plugin> abi_one_create(const nlohmann::json& options) {
  return std::make_unique<TestPairSelector>(options);
}
BOOST_DLL_ALIAS(abi_one_info, tessera_plugin_info)
BOOST_DLL_ALIAS(abi_one_create, tessera_plugin_create)

#elif defined(TESSERA_TEST_CASE_UNKNOWN_KIND)
extern "C" {
const TesseraPluginInfo unknown_kind_info = {
    TESSERA_PLUGIN_ABI_VERSION, "detectr",           "typo_kind", "1.0.0",
    "A kind with a typo",       TESSERA_BUILD_RECORD};
}
static std::unique_ptr<tessera::Plugin> unknown_kind_create(const nlohmann::json& options) {
  return std::make_unique<TestPairSelector>(options);
}
BOOST_DLL_ALIAS(unknown_kind_info, tessera_plugin_info)
BOOST_DLL_ALIAS(unknown_kind_create, tessera_plugin_create)

#elif defined(TESSERA_TEST_CASE_NO_FACTORY)
extern "C" {
const TesseraPluginInfo no_factory_info = {
    TESSERA_PLUGIN_ABI_VERSION, "pair_selector",     "no_factory", "1.0.0",
    "Info but no factory",      TESSERA_BUILD_RECORD};
}
BOOST_DLL_ALIAS(no_factory_info, tessera_plugin_info)

#elif defined(TESSERA_TEST_CASE_OLD_STRING_ABI)
// Compiled with -D_GLIBCXX_USE_CXX11_ABI=0: its std::string is not the host's.
TESSERA_PLUGIN(pair_selector, TestPairSelector, "old_string_abi", "1.0.0",
               "Built with the old libstdc++ string ABI")

#elif defined(TESSERA_TEST_CASE_FACTORY_THROWS)
TESSERA_PLUGIN(pair_selector, TestPairSelector, "throws", "1.0.0", "Its factory throws")

#elif defined(TESSERA_TEST_CASE_DUPLICATE_A) || defined(TESSERA_TEST_CASE_DUPLICATE_B)
TESSERA_PLUGIN(pair_selector, TestPairSelector, "twin", "1.0.0", "Two files claim this name")

#elif defined(TESSERA_TEST_CASE_FLOAT_ONLY)
// Not broken: a pair selector that refuses binary descriptors, as a retrieval selector
// with a float codebook does.
namespace {
class FloatOnlyPairSelector : public TestPairSelector {
 public:
  using TestPairSelector::TestPairSelector;
  void CheckDescriptors(tessera::DescriptorMetric metric, int /*dimension*/) const override {
    if (metric == tessera::DescriptorMetric::kHamming) {
      throw tessera::OptionError("", "needs float (L2) descriptors, not binary ones");
    }
  }
};
}  // namespace
TESSERA_PLUGIN(pair_selector, FloatOnlyPairSelector, "float_only", "1.0.0",
               "Refuses binary descriptors")

#elif defined(TESSERA_TEST_CASE_WRAPPING_A) || defined(TESSERA_TEST_CASE_WRAPPING_B)
// A bundle adjuster that wraps the one its option `wrap` names (made through the host,
// with `options`, in its constructor, or in each Adjust with `lazy`), or none:
// wrapping_a wrapping itself, or wrapping_b wrapping wrapping_a, is a loop the host must
// refuse; `level` is an option it can refuse.
namespace {
class WrappingBundleAdjuster : public tessera::BundleAdjuster {
 public:
  explicit WrappingBundleAdjuster(const nlohmann::json& options) {
    tessera::OptionReader reader(options);
    wrap_ = reader.GetString("wrap", "");
    wrapped_options_ = reader.GetJson("options", nlohmann::json::object());
    reader.Get<int>("level", 0, 0, 10);
    const bool lazy = reader.GetBool("lazy", false);
    reader.Finish();
    effective_options_ = reader.Effective();
    if (!wrap_.empty() && !lazy) wrapped_ = Make();
  }
  tessera::BundleAdjustmentSummary Adjust(const tessera::BundleAdjustmentConfig& config,
                                          tessera::Reconstruction* reconstruction) const override {
    if (wrapped_) return wrapped_->Adjust(config, reconstruction);
    if (!wrap_.empty()) return Make()->Adjust(config, reconstruction);
    tessera::BundleAdjustmentSummary summary;
    summary.usable = true;
    return summary;
  }

 private:
  std::unique_ptr<tessera::BundleAdjuster> Make() const {
    return host().Create<tessera::BundleAdjuster>("bundle_adjuster", wrap_, wrapped_options_);
  }

  std::string wrap_;
  nlohmann::json wrapped_options_;
  std::unique_ptr<tessera::BundleAdjuster> wrapped_;
};
}  // namespace
#if defined(TESSERA_TEST_CASE_WRAPPING_A)
TESSERA_PLUGIN(bundle_adjuster, WrappingBundleAdjuster, "wrapping_a", "1.0.0",
               "Wraps the bundle adjuster its options name")
#else
TESSERA_PLUGIN(bundle_adjuster, WrappingBundleAdjuster, "wrapping_b", "1.0.0",
               "Wraps the bundle adjuster its options name")
#endif

#elif defined(TESSERA_TEST_CASE_BAD_DESCRIPTION)
// Usable, but describes its options wrongly: a default outside the range it states.
static nlohmann::json DescribeWrongly() {
  return nlohmann::json::array({{{"name", "step"},
                                 {"type", "integer"},
                                 {"default", 0},
                                 {"min", 1},
                                 {"max", 9},
                                 {"help", "images apart"}}});
}
TESSERA_PLUGIN_OPTIONS_FROM(DescribeWrongly)
TESSERA_PLUGIN(pair_selector, TestPairSelector, "bad_description", "1.0.0",
               "Describes its options wrongly")

#elif defined(TESSERA_TEST_CASE_DESCRIBER_THROWS)
static nlohmann::json DescribeByThrowing() { throw std::runtime_error("no description today"); }
TESSERA_PLUGIN_OPTIONS_FROM(DescribeByThrowing)
TESSERA_PLUGIN(pair_selector, TestPairSelector, "describer_throws", "1.0.0",
               "Its option description throws")

#elif defined(TESSERA_TEST_CASE_GOOD)
TESSERA_PLUGIN(pair_selector, TestPairSelector, "consecutive", "1.2.3",
               "Each image with the next one")
#else
#error "define one TESSERA_TEST_CASE_* macro"
#endif
