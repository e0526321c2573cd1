#pragma once

// Everything a plugin author needs: include this, derive from one interface, and
// end the source file with TESSERA_PLUGIN(...).

#include <boost/dll/alias.hpp>
#include <type_traits>

#include "tessera/bundle_adjuster.h"
#include "tessera/camera.h"
#include "tessera/detector.h"
#include "tessera/errors.h"
#include "tessera/exporter.h"
#include "tessera/mapper.h"
#include "tessera/matcher.h"
#include "tessera/options.h"
#include "tessera/pair_selector.h"
#include "tessera/plugin.h"

namespace tessera::plugin_kinds {
// The interface of each kind, by the name used in TESSERA_PLUGIN and manifests.
using detector = ::tessera::Detector;
using matcher = ::tessera::Matcher;
using pair_selector = ::tessera::PairSelector;
using mapper = ::tessera::Mapper;
using bundle_adjuster = ::tessera::BundleAdjuster;
using exporter = ::tessera::Exporter;
}  // namespace tessera::plugin_kinds
