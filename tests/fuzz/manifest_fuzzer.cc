// The manifest parser: the bytes are a manifest file's contents. Invalid JSON and
// invalid manifests must be refused with InputError (OptionError is one).

#include <nlohmann/json.hpp>

#include "fuzz_support.h"
#include "manifest/manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  nlohmann::json json;
  try {
    // As Manifest::Load parses a file: comments allowed.
    json = nlohmann::json::parse(data, data + size, nullptr, true, /*ignore_comments=*/true);
  } catch (const nlohmann::json::parse_error&) {
    return 0;  // Load turns this into an InputError naming the file
  }
  tessera::fuzz::ExpectReadOrInputError("Manifest::FromJson", [&] {
    const tessera::Manifest manifest =
        tessera::Manifest::FromJson(json, tessera::fuzz::ScratchDir(), "fuzz.json");
    manifest.EffectiveNumThreads();
  });
  return 0;
}
