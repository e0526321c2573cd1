#include "plugin/guarded_exporter.h"

namespace tessera {

GuardedExporter::GuardedExporter(PluginInstance<Exporter> plugin) : plugin_(std::move(plugin)) {
  effective_options_ = plugin_.EffectiveOptions();
}

void GuardedExporter::Export(const Reconstruction& reconstruction,
                             const ExportContext& context) const {
  plugin_.Call(PluginStage::kExport, CurrentPluginSubject(),
               [&](const Exporter& exporter) { exporter.Export(reconstruction, context); });
}

}  // namespace tessera
