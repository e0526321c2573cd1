#include "toolbox/toolbox_outputs.h"

#include "outputs/output_transaction.h"
#include "tessera/errors.h"
#include "tessera/io/file_io.h"

namespace tessera {

ColmapModelFormat ColmapModelFormatOf(const std::filesystem::path& dir) {
  for (const char* name : {"cameras.bin", "images.bin", "points3D.bin"}) {
    if (!std::filesystem::is_regular_file(dir / name)) return ColmapModelFormat::kText;
  }
  return ColmapModelFormat::kBinary;
}

void CheckModelHasCamerasAndImages(const Reconstruction& model, const std::string& name) {
  if (model.cameras.empty()) throw InputError(name + ": has no cameras");
  if (model.NumRegisteredImages() == 0) throw InputError(name + ": has no registered images");
}

void WriteToolboxOutputs(const std::filesystem::path& output, const std::string& writer,
                         const Reconstruction& model, ColmapModelFormat format,
                         const ColmapModelFileOrder* order,
                         const std::function<void(const std::filesystem::path&)>& write_more) {
  CreateFolder(output);
  OutputTransaction outputs(output, OutputTransaction::Mode::kAddToSet);
  const std::filesystem::path staged = outputs.StageFor(writer);
  WriteColmapModel(model, staged, format, order);
  if (write_more) write_more(staged);
  outputs.Commit();
}

}  // namespace tessera
