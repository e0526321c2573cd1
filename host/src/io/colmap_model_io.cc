#include "tessera/io/colmap_model_io.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <iterator>
#include <locale>
#include <set>
#include <sstream>
#include <string>
#include <system_error>
#include <type_traits>

#include "names.h"
#include "tessera/errors.h"
#include "tessera/io/file_io.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

constexpr const char* kCamerasName = "cameras";
constexpr const char* kImagesName = "images";
constexpr const char* kPoints3DName = "points3D";

// Fixed parts of the binary records, used to reject a corrupt count before reserving.
constexpr size_t kCameraBinaryBytes = 4 + 4 + 8 + 8;         // id, model, width, height
constexpr size_t kImageBinaryBytes = 4 + 7 * 8 + 4 + 1 + 8;  // .., name's NUL, num points
constexpr size_t kPoint2DBinaryBytes = 8 + 8 + 8;
constexpr size_t kPoint3DBinaryBytes = 8 + 3 * 8 + 3 + 8 + 8;  // id, xyz, rgb, error, length
constexpr size_t kTrackElementBinaryBytes = 4 + 4;

// COLMAP 3.8's NormalizeQuaternion on (w, x, y, z), computed the same way so that
// normalizing a quaternion COLMAP wrote gives back the same bits.
Eigen::Vector4d NormalizeQvec(const Eigen::Vector4d& qvec) {
  const double norm = qvec.norm();
  if (norm == 0) return Eigen::Vector4d(1.0, qvec(1), qvec(2), qvec(3));
  return qvec / norm;
}

// A quaternion NormalizeQvec would turn into the identity, as COLMAP does: no rotation,
// so a reader refuses it rather than guess.
bool IsZeroQvec(const Eigen::Vector4d& qvec) { return qvec.norm() == 0; }

Eigen::Quaterniond QuaternionFromQvec(const Eigen::Vector4d& qvec) {
  const Eigen::Vector4d normalized = NormalizeQvec(qvec);
  return Eigen::Quaterniond(normalized(0), normalized(1), normalized(2), normalized(3));
}

Eigen::Vector4d QvecFromQuaternion(const Eigen::Quaterniond& rotation) {
  return NormalizeQvec(Eigen::Vector4d(rotation.w(), rotation.x(), rotation.y(), rotation.z()));
}

// ---------------------------------------------------------------------------
// Binary reading

class BinaryReader {
 public:
  BinaryReader(const fs::path& path) : path_(path), data_(ReadFileContents(path)) {}

  template <typename T>
  T Read(const std::string& what) {
    static_assert(std::is_arithmetic_v<T>);
    if (Remaining() < sizeof(T)) Fail("the file ends inside " + what);
    // The files are little-endian; assemble the value byte by byte so that the reader
    // is right on any host.
    std::make_unsigned_t<std::conditional_t<
        std::is_floating_point_v<T>, std::conditional_t<sizeof(T) == 8, int64_t, int32_t>, T>>
        bits = 0;
    for (size_t i = 0; i < sizeof(T); ++i) {
      bits |= static_cast<decltype(bits)>(static_cast<unsigned char>(data_[pos_ + i])) << (8 * i);
    }
    pos_ += sizeof(T);
    T value;
    std::memcpy(&value, &bits, sizeof(T));
    if constexpr (std::is_floating_point_v<T>) {
      // NaN or infinity would flow into every figure and into exports (as JSON null).
      if (!std::isfinite(value)) {
        pos_ -= sizeof(T);
        Fail(what + ": " + std::to_string(value) + " is not a finite number");
      }
    }
    return value;
  }

  std::string ReadString(const std::string& what) {
    const size_t end = data_.find('\0', pos_);
    if (end == std::string::npos) Fail("the file ends inside " + what);
    std::string value = data_.substr(pos_, end - pos_);
    pos_ = end + 1;
    return value;
  }

  // A count read from the file, checked against the bytes left so that a corrupt count
  // fails here instead of reserving huge memory or looping for long.
  uint64_t ReadCount(size_t min_bytes_per_item, const std::string& what) {
    const auto count = Read<uint64_t>("the number of " + what);
    if (count > Remaining() / min_bytes_per_item) {
      Fail("it claims " + std::to_string(count) + " " + what + " but only " +
           std::to_string(Remaining()) + " bytes follow");
    }
    return count;
  }

  void ExpectEnd() const {
    if (Remaining() != 0) {
      Fail(std::to_string(Remaining()) + " unexpected bytes follow the last record");
    }
  }

  [[noreturn]] void Fail(const std::string& message) const {
    throw InputError(path_.string() + " is truncated or malformed at byte " + std::to_string(pos_) +
                     ": " + message + ".");
  }

  size_t Remaining() const { return data_.size() - pos_; }

 private:
  fs::path path_;
  std::string data_;
  size_t pos_ = 0;
};

void ReadCamerasBinary(const fs::path& path, Reconstruction* reconstruction,
                       std::vector<camera_t>* order) {
  BinaryReader reader(path);
  const uint64_t num_cameras = reader.ReadCount(kCameraBinaryBytes, "cameras");
  for (uint64_t i = 0; i < num_cameras; ++i) {
    Camera camera;
    camera.camera_id = reader.Read<camera_t>("a camera id");
    const std::string what = "camera " + std::to_string(camera.camera_id);
    const int model_id = reader.Read<int32_t>("the model of " + what);
    if (!ExistsCameraModelWithId(model_id)) {
      reader.Fail(what + " has the unknown camera model id " + std::to_string(model_id));
    }
    camera.model_id = static_cast<CameraModelId>(model_id);
    camera.width = reader.Read<uint64_t>("the width of " + what);
    camera.height = reader.Read<uint64_t>("the height of " + what);
    camera.params.resize(CameraModelNumParams(camera.model_id));
    for (double& param : camera.params) param = reader.Read<double>("the parameters of " + what);
    camera.calibration_source = CalibrationSource::kDatabase;
    if (!reconstruction->cameras.emplace(camera.camera_id, camera).second) {
      reader.Fail("the camera id " + std::to_string(camera.camera_id) + " appears twice");
    }
    order->push_back(camera.camera_id);
  }
  reader.ExpectEnd();
}

void ReadImagesBinary(const fs::path& path, Reconstruction* reconstruction,
                      std::vector<image_t>* order) {
  BinaryReader reader(path);
  const uint64_t num_images = reader.ReadCount(kImageBinaryBytes, "images");
  for (uint64_t i = 0; i < num_images; ++i) {
    Image image;
    image.image_id = reader.Read<image_t>("an image id");
    const std::string what = "image " + std::to_string(image.image_id);
    Eigen::Vector4d qvec;
    for (int k = 0; k < 4; ++k) qvec(k) = reader.Read<double>("the rotation of " + what);
    if (IsZeroQvec(qvec)) reader.Fail("the rotation of " + what + " has length 0");
    image.cam_from_world.rotation = QuaternionFromQvec(qvec);
    for (int k = 0; k < 3; ++k) {
      image.cam_from_world.translation(k) = reader.Read<double>("the translation of " + what);
    }
    image.camera_id = reader.Read<camera_t>("the camera id of " + what);
    image.name = reader.ReadString("the name of " + what);
    CheckImageName(image.name, path.string() + ": " + what);
    image.registered = true;
    const uint64_t num_points2D =
        reader.ReadCount(kPoint2DBinaryBytes, "2D points of " + what + " (" + image.name + ")");
    image.points2D.resize(num_points2D);
    for (Point2D& point2D : image.points2D) {
      point2D.xy.x() = reader.Read<double>("a 2D point of " + what);
      point2D.xy.y() = reader.Read<double>("a 2D point of " + what);
      point2D.point3D_id = reader.Read<point3D_t>("a 2D point of " + what);
    }
    const image_t image_id = image.image_id;
    if (!reconstruction->images.emplace(image_id, std::move(image)).second) {
      reader.Fail("the image id " + std::to_string(image_id) + " appears twice");
    }
    order->push_back(image_id);
  }
  reader.ExpectEnd();
}

void ReadPoints3DBinary(const fs::path& path, Reconstruction* reconstruction,
                        std::vector<point3D_t>* order) {
  BinaryReader reader(path);
  const uint64_t num_points3D = reader.ReadCount(kPoint3DBinaryBytes, "3D points");
  for (uint64_t i = 0; i < num_points3D; ++i) {
    Point3D point3D;
    const auto point3D_id = reader.Read<point3D_t>("a 3D point id");
    const std::string what = "3D point " + std::to_string(point3D_id);
    for (int k = 0; k < 3; ++k) point3D.xyz(k) = reader.Read<double>("the position of " + what);
    for (int k = 0; k < 3; ++k) point3D.color(k) = reader.Read<uint8_t>("the colour of " + what);
    point3D.error = reader.Read<double>("the error of " + what);
    const uint64_t track_length =
        reader.ReadCount(kTrackElementBinaryBytes, "track elements of " + what);
    point3D.track.resize(track_length);
    for (TrackElement& element : point3D.track) {
      element.image_id = reader.Read<image_t>("the track of " + what);
      element.point2D_idx = reader.Read<point2D_t>("the track of " + what);
    }
    if (!reconstruction->points3D.emplace(point3D_id, std::move(point3D)).second) {
      reader.Fail("the 3D point id " + std::to_string(point3D_id) + " appears twice");
    }
    order->push_back(point3D_id);
  }
  reader.ExpectEnd();
}

// ---------------------------------------------------------------------------
// Text reading

// Whitespace-separated fields of one line, with the file and line for messages.
class TextLine {
 public:
  TextLine(const fs::path& path, size_t line_number, const std::string& text)
      : path_(path), line_number_(line_number), text_(text) {
    size_t pos = 0;
    while (true) {
      pos = text_.find_first_not_of(" \t\r", pos);
      if (pos == std::string::npos) break;
      const size_t end = std::min(text_.find_first_of(" \t\r", pos), text_.size());
      fields_.emplace_back(pos, end - pos);
      pos = end;
    }
  }

  size_t NumFields() const { return fields_.size(); }

  std::string_view Field(size_t index) const {
    return std::string_view(text_).substr(fields_[index].first, fields_[index].second);
  }

  // The rest of the line from field `index` on, trimmed: image names may hold spaces.
  std::string Rest(size_t index) const {
    const size_t begin = fields_[index].first;
    const size_t end = fields_.back().first + fields_.back().second;
    return text_.substr(begin, end - begin);
  }

  template <typename T>
  T Parse(size_t index, const std::string& what) const {
    if (index >= fields_.size()) Fail("missing " + what);
    const std::string_view field = Field(index);
    T value{};
    const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
    if (error != std::errc() || end != field.data() + field.size()) {
      Fail("'" + std::string(field) + "' is not a valid " + what);
    }
    if constexpr (std::is_floating_point_v<T>) {
      // from_chars reads "nan" and "inf"; a model holds finite numbers only.
      if (!std::isfinite(value)) Fail("'" + std::string(field) + "' is not a finite " + what);
    }
    return value;
  }

  [[noreturn]] void Fail(const std::string& message) const {
    throw InputError(path_.string() + " line " + std::to_string(line_number_) + ": " + message +
                     ".");
  }

 private:
  const fs::path& path_;
  size_t line_number_;
  const std::string& text_;
  std::vector<std::pair<size_t, size_t>> fields_;
};

// Lines of a text model file; comments (#) and blank lines are skipped by NextData(),
// while NextRaw() returns the very next line, as COLMAP reads an image's 2D points.
class TextReader {
 public:
  explicit TextReader(const fs::path& path) : path_(path), stream_(ReadFileContents(path)) {}

  bool NextData() {
    while (NextRaw()) {
      const size_t first = line_.find_first_not_of(" \t\r");
      if (first != std::string::npos && line_[first] != '#') return true;
    }
    return false;
  }

  bool NextRaw() {
    if (!std::getline(stream_, line_)) return false;
    ++line_number_;
    return true;
  }

  TextLine Line() const { return TextLine(path_, line_number_, line_); }
  size_t line_number() const { return line_number_; }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
  std::istringstream stream_;
  std::string line_;
  size_t line_number_ = 0;
};

void ReadCamerasText(const fs::path& path, Reconstruction* reconstruction,
                     std::vector<camera_t>* order) {
  TextReader reader(path);
  while (reader.NextData()) {
    const TextLine line = reader.Line();
    Camera camera;
    camera.camera_id = line.Parse<camera_t>(0, "camera id");
    if (line.NumFields() < 2) line.Fail("missing camera model");
    const std::string model_name(line.Field(1));
    camera.model_id = CameraModelNameToId(model_name);
    if (camera.model_id == CameraModelId::kInvalid) {
      line.Fail("unknown camera model '" + model_name + "'");
    }
    camera.width = line.Parse<uint64_t>(2, "width");
    camera.height = line.Parse<uint64_t>(3, "height");
    const size_t num_params = CameraModelNumParams(camera.model_id);
    if (line.NumFields() != 4 + num_params) {
      line.Fail(model_name + " takes " + std::to_string(num_params) + " parameters, found " +
                std::to_string(line.NumFields() - std::min<size_t>(line.NumFields(), 4)));
    }
    for (size_t i = 0; i < num_params; ++i) {
      camera.params.push_back(line.Parse<double>(4 + i, "camera parameter"));
    }
    camera.calibration_source = CalibrationSource::kDatabase;
    if (!reconstruction->cameras.emplace(camera.camera_id, camera).second) {
      line.Fail("the camera id " + std::to_string(camera.camera_id) + " appears twice");
    }
    order->push_back(camera.camera_id);
  }
}

void ReadImagesText(const fs::path& path, Reconstruction* reconstruction,
                    std::vector<image_t>* order) {
  TextReader reader(path);
  while (reader.NextData()) {
    const TextLine line = reader.Line();
    Image image;
    image.image_id = line.Parse<image_t>(0, "image id");
    Eigen::Vector4d qvec;
    for (int k = 0; k < 4; ++k) qvec(k) = line.Parse<double>(1 + k, "quaternion component");
    if (IsZeroQvec(qvec)) {
      line.Fail("the rotation of image " + std::to_string(image.image_id) + " has length 0");
    }
    image.cam_from_world.rotation = QuaternionFromQvec(qvec);
    for (int k = 0; k < 3; ++k) {
      image.cam_from_world.translation(k) = line.Parse<double>(5 + k, "translation component");
    }
    image.camera_id = line.Parse<camera_t>(8, "camera id");
    if (line.NumFields() < 10) line.Fail("missing image name");
    image.name = line.Rest(9);
    CheckImageName(image.name, path.string() + " line " + std::to_string(reader.line_number()) +
                                   ": image " + std::to_string(image.image_id));
    image.registered = true;

    if (!reader.NextRaw()) {
      throw InputError(path.string() + " ends after line " + std::to_string(reader.line_number()) +
                       ": the 2D points line of image " + std::to_string(image.image_id) +
                       " is missing.");
    }
    const TextLine points_line = reader.Line();
    if (points_line.NumFields() % 3 != 0) {
      points_line.Fail("the 2D points of image " + std::to_string(image.image_id) +
                       " are not triplets X Y POINT3D_ID");
    }
    image.points2D.resize(points_line.NumFields() / 3);
    for (size_t i = 0; i < image.points2D.size(); ++i) {
      Point2D& point2D = image.points2D[i];
      point2D.xy.x() = points_line.Parse<double>(3 * i, "2D point x");
      point2D.xy.y() = points_line.Parse<double>(3 * i + 1, "2D point y");
      if (points_line.Field(3 * i + 2) == "-1") {
        point2D.point3D_id = kInvalidPoint3DId;
      } else {
        point2D.point3D_id = points_line.Parse<point3D_t>(3 * i + 2, "3D point id");
      }
    }
    const image_t image_id = image.image_id;
    if (!reconstruction->images.emplace(image_id, std::move(image)).second) {
      line.Fail("the image id " + std::to_string(image_id) + " appears twice");
    }
    order->push_back(image_id);
  }
}

void ReadPoints3DText(const fs::path& path, Reconstruction* reconstruction,
                      std::vector<point3D_t>* order) {
  TextReader reader(path);
  while (reader.NextData()) {
    const TextLine line = reader.Line();
    Point3D point3D;
    const auto point3D_id = line.Parse<point3D_t>(0, "3D point id");
    for (int k = 0; k < 3; ++k) point3D.xyz(k) = line.Parse<double>(1 + k, "coordinate");
    for (int k = 0; k < 3; ++k) {
      const auto channel = line.Parse<unsigned>(4 + k, "colour channel");
      if (channel > 255)
        line.Fail("the colour channel " + std::to_string(channel) + " is over 255");
      point3D.color(k) = static_cast<uint8_t>(channel);
    }
    point3D.error = line.Parse<double>(7, "error");
    if ((line.NumFields() - 8) % 2 != 0) {
      line.Fail("the track of 3D point " + std::to_string(point3D_id) +
                " is not pairs IMAGE_ID POINT2D_IDX");
    }
    point3D.track.resize((line.NumFields() - 8) / 2);
    for (size_t i = 0; i < point3D.track.size(); ++i) {
      point3D.track[i].image_id = line.Parse<image_t>(8 + 2 * i, "track image id");
      point3D.track[i].point2D_idx = line.Parse<point2D_t>(9 + 2 * i, "track 2D point index");
    }
    if (!reconstruction->points3D.emplace(point3D_id, std::move(point3D)).second) {
      line.Fail("the 3D point id " + std::to_string(point3D_id) + " appears twice");
    }
    order->push_back(point3D_id);
  }
}

// Cross-file references, checked so that code using the model may index without checks.
void CheckConsistency(const Reconstruction& reconstruction, const fs::path& images_path,
                      const fs::path& points3D_path) {
  for (const auto& [image_id, image] : reconstruction.images) {
    if (reconstruction.cameras.count(image.camera_id) == 0) {
      throw InputError(images_path.string() + ": image " + std::to_string(image_id) + " (" +
                       image.name + ") refers to camera " + std::to_string(image.camera_id) +
                       ", which the cameras file does not hold.");
    }
  }
  for (const auto& [point3D_id, point3D] : reconstruction.points3D) {
    for (const TrackElement& element : point3D.track) {
      const auto image = reconstruction.images.find(element.image_id);
      if (image == reconstruction.images.end()) {
        throw InputError(points3D_path.string() + ": the track of 3D point " +
                         std::to_string(point3D_id) + " refers to image " +
                         std::to_string(element.image_id) +
                         ", which the images file does not hold.");
      }
      if (element.point2D_idx >= image->second.points2D.size()) {
        throw InputError(points3D_path.string() + ": the track of 3D point " +
                         std::to_string(point3D_id) + " refers to 2D point " +
                         std::to_string(element.point2D_idx) + " of image " +
                         std::to_string(element.image_id) + ", which has only " +
                         std::to_string(image->second.points2D.size()) + ".");
      }
    }
  }
  for (const auto& [image_id, image] : reconstruction.images) {
    for (size_t i = 0; i < image.points2D.size(); ++i) {
      const point3D_t point3D_id = image.points2D[i].point3D_id;
      if (point3D_id != kInvalidPoint3DId && reconstruction.points3D.count(point3D_id) == 0) {
        throw InputError(images_path.string() + ": 2D point " + std::to_string(i) + " of image " +
                         std::to_string(image_id) + " refers to 3D point " +
                         std::to_string(point3D_id) + ", which the points3D file does not hold.");
      }
    }
  }
}

fs::path ModelFile(const fs::path& dir, const char* name, const char* extension) {
  return dir / (std::string(name) + extension);
}

bool HasAllFiles(const fs::path& dir, const char* extension) {
  std::error_code error;
  for (const char* name : {kCamerasName, kImagesName, kPoints3DName}) {
    if (!fs::is_regular_file(ModelFile(dir, name, extension), error)) return false;
  }
  return true;
}

// ---------------------------------------------------------------------------
// Writing

// Ids of `map` in the order `preferred` lists them, then the rest ascending.
template <typename Id, typename Value>
std::vector<Id> WriteOrder(const std::map<Id, Value>& map, const std::vector<Id>* preferred) {
  std::vector<Id> ids;
  ids.reserve(map.size());
  std::set<Id> taken;
  if (preferred != nullptr) {
    for (const Id id : *preferred) {
      if (map.count(id) != 0 && taken.insert(id).second) ids.push_back(id);
    }
  }
  for (const auto& [id, value] : map) {
    if (taken.count(id) == 0) ids.push_back(id);
  }
  return ids;
}

template <typename T>
void PutBinary(std::string* buffer, T value) {
  static_assert(std::is_arithmetic_v<T>);
  std::make_unsigned_t<std::conditional_t<std::is_floating_point_v<T>,
                                          std::conditional_t<sizeof(T) == 8, int64_t, int32_t>, T>>
      bits;
  std::memcpy(&bits, &value, sizeof(T));
  for (size_t i = 0; i < sizeof(T); ++i) buffer->push_back(static_cast<char>(bits >> (8 * i)));
}

// A stream that prints numbers as COLMAP 3.8's text writer does.
std::ostringstream MakeTextStream() {
  std::ostringstream stream;
  stream.imbue(std::locale::classic());
  stream.precision(17);
  return stream;
}

// Keypoints of registered images with a 3D point: what the headers of COLMAP's text
// files count (the track view, NumObservations in model_statistics.h, gives the same
// number for a consistent model).
size_t NumRegisteredImageObservations(const Reconstruction& reconstruction) {
  size_t num_observations = 0;
  for (const auto& [image_id, image] : reconstruction.images) {
    if (!image.registered) continue;
    for (const Point2D& point2D : image.points2D) num_observations += point2D.HasPoint3D();
  }
  return num_observations;
}

std::string CamerasBinary(const Reconstruction& reconstruction, const std::vector<camera_t>& ids) {
  std::string buffer;
  PutBinary<uint64_t>(&buffer, ids.size());
  for (const camera_t camera_id : ids) {
    const Camera& camera = reconstruction.cameras.at(camera_id);
    PutBinary<camera_t>(&buffer, camera_id);
    PutBinary<int32_t>(&buffer, static_cast<int32_t>(camera.model_id));
    PutBinary<uint64_t>(&buffer, camera.width);
    PutBinary<uint64_t>(&buffer, camera.height);
    for (const double param : camera.params) PutBinary<double>(&buffer, param);
  }
  return buffer;
}

std::string ImagesBinary(const Reconstruction& reconstruction, const std::vector<image_t>& ids) {
  std::string buffer;
  PutBinary<uint64_t>(&buffer, ids.size());
  for (const image_t image_id : ids) {
    const Image& image = reconstruction.images.at(image_id);
    PutBinary<image_t>(&buffer, image_id);
    const Eigen::Vector4d qvec = QvecFromQuaternion(image.cam_from_world.rotation);
    for (int k = 0; k < 4; ++k) PutBinary<double>(&buffer, qvec(k));
    for (int k = 0; k < 3; ++k) PutBinary<double>(&buffer, image.cam_from_world.translation(k));
    PutBinary<camera_t>(&buffer, image.camera_id);
    buffer.append(image.name);
    buffer.push_back('\0');
    PutBinary<uint64_t>(&buffer, image.points2D.size());
    for (const Point2D& point2D : image.points2D) {
      PutBinary<double>(&buffer, point2D.xy.x());
      PutBinary<double>(&buffer, point2D.xy.y());
      PutBinary<point3D_t>(&buffer, point2D.point3D_id);
    }
  }
  return buffer;
}

std::string Points3DBinary(const Reconstruction& reconstruction,
                           const std::vector<point3D_t>& ids) {
  std::string buffer;
  PutBinary<uint64_t>(&buffer, ids.size());
  for (const point3D_t point3D_id : ids) {
    const Point3D& point3D = reconstruction.points3D.at(point3D_id);
    PutBinary<point3D_t>(&buffer, point3D_id);
    for (int k = 0; k < 3; ++k) PutBinary<double>(&buffer, point3D.xyz(k));
    for (int k = 0; k < 3; ++k) PutBinary<uint8_t>(&buffer, point3D.color(k));
    PutBinary<double>(&buffer, point3D.error);
    PutBinary<uint64_t>(&buffer, point3D.track.size());
    for (const TrackElement& element : point3D.track) {
      PutBinary<image_t>(&buffer, element.image_id);
      PutBinary<point2D_t>(&buffer, element.point2D_idx);
    }
  }
  return buffer;
}

// The text writers reproduce COLMAP 3.8's output exactly, down to its quirks: a 3D point
// without a track keeps the space after its error, an image without 2D points gets an
// empty line.
std::string CamerasText(const Reconstruction& reconstruction, const std::vector<camera_t>& ids) {
  std::ostringstream text = MakeTextStream();
  text << "# Camera list with one line of data per camera:\n"
       << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
       << "# Number of cameras: " << ids.size() << "\n";
  for (const camera_t camera_id : ids) {
    const Camera& camera = reconstruction.cameras.at(camera_id);
    text << camera_id << " " << camera.ModelName() << " " << camera.width << " " << camera.height;
    for (const double param : camera.params) text << " " << param;
    text << "\n";
  }
  return text.str();
}

std::string ImagesText(const Reconstruction& reconstruction, const std::vector<image_t>& ids) {
  const size_t num_observations = NumRegisteredImageObservations(reconstruction);
  std::ostringstream text = MakeTextStream();
  text << "# Image list with two lines of data per image:\n"
       << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
       << "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
       << "# Number of images: " << ids.size() << ", mean observations per image: "
       << (ids.empty() ? 0.0 : num_observations / static_cast<double>(ids.size())) << "\n";
  for (const image_t image_id : ids) {
    const Image& image = reconstruction.images.at(image_id);
    const Eigen::Vector4d qvec = QvecFromQuaternion(image.cam_from_world.rotation);
    const Eigen::Vector3d& tvec = image.cam_from_world.translation;
    text << image_id << " " << qvec(0) << " " << qvec(1) << " " << qvec(2) << " " << qvec(3) << " "
         << tvec(0) << " " << tvec(1) << " " << tvec(2) << " " << image.camera_id << " "
         << image.name << "\n";
    for (size_t i = 0; i < image.points2D.size(); ++i) {
      const Point2D& point2D = image.points2D[i];
      if (i > 0) text << " ";
      text << point2D.xy.x() << " " << point2D.xy.y() << " ";
      if (point2D.HasPoint3D()) {
        text << point2D.point3D_id;
      } else {
        text << -1;
      }
    }
    text << "\n";
  }
  return text.str();
}

std::string Points3DText(const Reconstruction& reconstruction, const std::vector<point3D_t>& ids) {
  const size_t num_observations = NumRegisteredImageObservations(reconstruction);
  std::ostringstream text = MakeTextStream();
  text << "# 3D point list with one line of data per point:\n"
       << "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
       << "# Number of points: " << ids.size() << ", mean track length: "
       << (ids.empty() ? 0.0 : num_observations / static_cast<double>(ids.size())) << "\n";
  for (const point3D_t point3D_id : ids) {
    const Point3D& point3D = reconstruction.points3D.at(point3D_id);
    text << point3D_id << " " << point3D.xyz(0) << " " << point3D.xyz(1) << " " << point3D.xyz(2)
         << " " << static_cast<int>(point3D.color(0)) << " " << static_cast<int>(point3D.color(1))
         << " " << static_cast<int>(point3D.color(2)) << " " << point3D.error << " ";
    for (size_t i = 0; i < point3D.track.size(); ++i) {
      if (i > 0) text << " ";
      text << point3D.track[i].image_id << " " << point3D.track[i].point2D_idx;
    }
    text << "\n";
  }
  return text.str();
}

}  // namespace

bool ExistsColmapModel(const fs::path& dir) {
  return HasAllFiles(dir, ".bin") || HasAllFiles(dir, ".txt");
}

Reconstruction ReadColmapModel(const fs::path& dir, ColmapModelFileOrder* order) {
  ColmapModelFileOrder file_order;
  Reconstruction reconstruction;
  fs::path images_path, points3D_path;
  if (HasAllFiles(dir, ".bin")) {
    images_path = ModelFile(dir, kImagesName, ".bin");
    points3D_path = ModelFile(dir, kPoints3DName, ".bin");
    ReadCamerasBinary(ModelFile(dir, kCamerasName, ".bin"), &reconstruction,
                      &file_order.camera_ids);
    ReadImagesBinary(images_path, &reconstruction, &file_order.image_ids);
    ReadPoints3DBinary(points3D_path, &reconstruction, &file_order.point3D_ids);
  } else if (HasAllFiles(dir, ".txt")) {
    images_path = ModelFile(dir, kImagesName, ".txt");
    points3D_path = ModelFile(dir, kPoints3DName, ".txt");
    ReadCamerasText(ModelFile(dir, kCamerasName, ".txt"), &reconstruction, &file_order.camera_ids);
    ReadImagesText(images_path, &reconstruction, &file_order.image_ids);
    ReadPoints3DText(points3D_path, &reconstruction, &file_order.point3D_ids);
  } else {
    throw InputError(dir.string() +
                     " is not a COLMAP model: it lacks cameras, images and points3D as .bin or "
                     ".txt files.");
  }
  CheckConsistency(reconstruction, images_path, points3D_path);
  if (order != nullptr) *order = std::move(file_order);
  return reconstruction;
}

void WriteColmapModel(const Reconstruction& reconstruction, const fs::path& dir,
                      ColmapModelFormat format, const ColmapModelFileOrder* order) {
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) {
    throw InputError("Cannot create the model folder " + dir.string() + ": " + error.message() +
                     ".");
  }
  const std::vector<camera_t> camera_ids =
      WriteOrder(reconstruction.cameras, order != nullptr ? &order->camera_ids : nullptr);
  std::vector<image_t> image_ids =
      WriteOrder(reconstruction.images, order != nullptr ? &order->image_ids : nullptr);
  image_ids.erase(std::remove_if(image_ids.begin(), image_ids.end(),
                                 [&](image_t image_id) {
                                   return !reconstruction.images.at(image_id).registered;
                                 }),
                  image_ids.end());
  const std::vector<point3D_t> point3D_ids =
      WriteOrder(reconstruction.points3D, order != nullptr ? &order->point3D_ids : nullptr);

  if (format == ColmapModelFormat::kBinary) {
    WriteFileAtomically(ModelFile(dir, kCamerasName, ".bin"),
                        CamerasBinary(reconstruction, camera_ids));
    WriteFileAtomically(ModelFile(dir, kImagesName, ".bin"),
                        ImagesBinary(reconstruction, image_ids));
    WriteFileAtomically(ModelFile(dir, kPoints3DName, ".bin"),
                        Points3DBinary(reconstruction, point3D_ids));
  } else {
    WriteFileAtomically(ModelFile(dir, kCamerasName, ".txt"),
                        CamerasText(reconstruction, camera_ids));
    WriteFileAtomically(ModelFile(dir, kImagesName, ".txt"), ImagesText(reconstruction, image_ids));
    WriteFileAtomically(ModelFile(dir, kPoints3DName, ".txt"),
                        Points3DText(reconstruction, point3D_ids));
  }
}

}  // namespace tessera
