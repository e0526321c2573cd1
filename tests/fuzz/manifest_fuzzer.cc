// The manifest parser: the bytes are a manifest file, read with Manifest::Load as the
// command line reads --manifest. Invalid JSON and invalid manifests must be refused
// with InputError (OptionError is one).

#include "fuzz_support.h"
#include "manifest/manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::filesystem::path path = tessera::fuzz::ScratchDir() / "manifest.json";
  tessera::fuzz::WriteFile(path, std::string_view(reinterpret_cast<const char*>(data), size));
  tessera::fuzz::ExpectReadOrInputError("Manifest::Load", [&] {
    const tessera::Manifest manifest = tessera::Manifest::Load(path);
    manifest.EffectiveNumThreads();
  });
  return 0;
}
