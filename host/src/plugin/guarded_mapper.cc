#include "plugin/guarded_mapper.h"

namespace tessera {

GuardedMapper::GuardedMapper(PluginInstance<Mapper> plugin) : plugin_(std::move(plugin)) {
  effective_options_ = plugin_.EffectiveOptions();
}

MapperResult GuardedMapper::Map(const MapperInput& input, const MapperContext& context) const {
  return plugin_.Call(PluginStage::kMap, CurrentPluginSubject(),
                      [&](const Mapper& mapper) { return mapper.Map(input, context); });
}

}  // namespace tessera
