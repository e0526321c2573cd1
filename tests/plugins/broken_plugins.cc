// Deliberately broken plugins, one per way the loader must refuse a plugin. Each is
// compiled into its own folder with one TESSERA_TEST_CASE_* macro defined; see
// tests/CMakeLists.txt.

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

}  // namespace

#if defined(TESSERA_TEST_CASE_NO_INFO)
// Exports a function, but no info record.
extern "C" __attribute__((visibility("default"))) int tessera_unrelated_symbol() { return 42; }

#elif defined(TESSERA_TEST_CASE_WRONG_ABI)
extern "C" {
const TesseraPluginInfo wrong_abi_info = {999, "pair_selector", "future", "9.0.0",
                                          "From the future"};
}
static std::unique_ptr<tessera::Plugin> wrong_abi_create(const nlohmann::json& options) {
  return std::make_unique<TestPairSelector>(options);
}
BOOST_DLL_ALIAS(wrong_abi_info, tessera_plugin_info)
BOOST_DLL_ALIAS(wrong_abi_create, tessera_plugin_create)

#elif defined(TESSERA_TEST_CASE_ABI_ONE)
// A plugin built against ABI 1 (pair selectors saw only file names): its record says 1.
extern "C" {
const TesseraPluginInfo abi_one_info = {1, "pair_selector", "names_only", "1.0.0",
                                        "Built against ABI 1"};
}
static std::unique_ptr<tessera::Plugin> abi_one_create(const nlohmann::json& options) {
  return std::make_unique<TestPairSelector>(options);
}
BOOST_DLL_ALIAS(abi_one_info, tessera_plugin_info)
BOOST_DLL_ALIAS(abi_one_create, tessera_plugin_create)

#elif defined(TESSERA_TEST_CASE_UNKNOWN_KIND)
extern "C" {
const TesseraPluginInfo unknown_kind_info = {TESSERA_PLUGIN_ABI_VERSION, "detectr", "typo_kind",
                                             "1.0.0", "A kind with a typo"};
}
static std::unique_ptr<tessera::Plugin> unknown_kind_create(const nlohmann::json& options) {
  return std::make_unique<TestPairSelector>(options);
}
BOOST_DLL_ALIAS(unknown_kind_info, tessera_plugin_info)
BOOST_DLL_ALIAS(unknown_kind_create, tessera_plugin_create)

#elif defined(TESSERA_TEST_CASE_NO_FACTORY)
extern "C" {
const TesseraPluginInfo no_factory_info = {TESSERA_PLUGIN_ABI_VERSION, "pair_selector",
                                           "no_factory", "1.0.0", "Info but no factory"};
}
BOOST_DLL_ALIAS(no_factory_info, tessera_plugin_info)

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

#elif defined(TESSERA_TEST_CASE_GOOD)
TESSERA_PLUGIN(pair_selector, TestPairSelector, "consecutive", "1.2.3",
               "Each image with the next one")
#else
#error "define one TESSERA_TEST_CASE_* macro"
#endif
