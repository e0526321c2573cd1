#include "image/exif.h"

#include <libexif/exif-data.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

namespace tessera {
namespace {

struct ExifDataDeleter {
  void operator()(ExifData* data) const { exif_data_unref(data); }
};

// The entry of `tag`, looked up in the IFD where the standard puts it first and in
// the others after, since some cameras put tags in the wrong IFD.
ExifEntry* FindEntry(ExifData* data, ExifIfd preferred_ifd, ExifTag tag) {
  if (ExifEntry* entry = exif_content_get_entry(data->ifd[preferred_ifd], tag)) return entry;
  // IFD 1 describes the thumbnail; its Orientation or size must not stand in for the image's.
  for (const ExifIfd ifd : {EXIF_IFD_0, EXIF_IFD_EXIF, EXIF_IFD_INTEROPERABILITY}) {
    if (ifd == preferred_ifd) continue;
    if (ExifEntry* entry = exif_content_get_entry(data->ifd[ifd], tag)) return entry;
  }
  return nullptr;
}

bool HasComponent(const ExifEntry* entry, ExifFormat format) {
  return entry != nullptr && entry->format == format && entry->components >= 1 &&
         entry->data != nullptr && entry->size >= exif_format_get_size(format);
}

std::string ReadAscii(ExifEntry* entry) {
  if (entry == nullptr || entry->data == nullptr) return "";
  std::string text(reinterpret_cast<const char*>(entry->data), entry->size);
  text = text.substr(0, text.find('\0'));
  const auto not_space = [](unsigned char c) { return !std::isspace(c); };
  text.erase(text.begin(), std::find_if(text.begin(), text.end(), not_space));
  text.erase(std::find_if(text.rbegin(), text.rend(), not_space).base(), text.end());
  return text;
}

std::optional<double> ReadRational(ExifEntry* entry, ExifByteOrder order) {
  if (HasComponent(entry, EXIF_FORMAT_RATIONAL)) {
    const ExifRational value = exif_get_rational(entry->data, order);
    if (value.denominator == 0) return std::nullopt;
    return static_cast<double>(value.numerator) / value.denominator;
  }
  if (HasComponent(entry, EXIF_FORMAT_SRATIONAL)) {
    const ExifSRational value = exif_get_srational(entry->data, order);
    if (value.denominator == 0) return std::nullopt;
    return static_cast<double>(value.numerator) / value.denominator;
  }
  return std::nullopt;
}

// SHORT or LONG, as the standard allows either for several tags.
std::optional<int64_t> ReadInteger(ExifEntry* entry, ExifByteOrder order) {
  if (HasComponent(entry, EXIF_FORMAT_SHORT)) return exif_get_short(entry->data, order);
  if (HasComponent(entry, EXIF_FORMAT_LONG)) return exif_get_long(entry->data, order);
  if (HasComponent(entry, EXIF_FORMAT_SSHORT)) return exif_get_sshort(entry->data, order);
  if (HasComponent(entry, EXIF_FORMAT_SLONG)) return exif_get_slong(entry->data, order);
  return std::nullopt;
}

// Millimetres per FocalPlaneResolutionUnit; 0 when the unit has no absolute size.
double MillimetresPerUnit(int64_t unit) {
  switch (unit) {
    case 2:
      return 25.4;  // inch (the default)
    case 3:
      return 10;  // centimetre
    case 4:
      return 1;  // millimetre (not in the standard, written by some cameras)
    case 5:
      return 1e-3;  // micrometre (likewise)
    default:
      return 0;
  }
}

}  // namespace

ExifInfo ReadExifInfo(const unsigned char* data, size_t size) {
  ExifInfo info;
  if (data == nullptr || size == 0) return info;
  std::unique_ptr<ExifData, ExifDataDeleter> exif(exif_data_new());
  if (!exif) return info;
  // Following the specification would add missing mandatory tags with made-up
  // defaults; we want to see only what the camera wrote.
  exif_data_unset_option(exif.get(), EXIF_DATA_OPTION_FOLLOW_SPECIFICATION);
  exif_data_load_data(exif.get(), data,
                      static_cast<unsigned int>(std::min<size_t>(size, UINT_MAX)));
  const ExifByteOrder order = exif_data_get_byte_order(exif.get());

  info.make = ReadAscii(FindEntry(exif.get(), EXIF_IFD_0, EXIF_TAG_MAKE));
  info.model = ReadAscii(FindEntry(exif.get(), EXIF_IFD_0, EXIF_TAG_MODEL));
  if (auto orientation =
          ReadInteger(FindEntry(exif.get(), EXIF_IFD_0, EXIF_TAG_ORIENTATION), order)) {
    if (*orientation >= 1 && *orientation <= 8) info.orientation = static_cast<int>(*orientation);
  }
  info.focal_length_mm =
      ReadRational(FindEntry(exif.get(), EXIF_IFD_EXIF, EXIF_TAG_FOCAL_LENGTH), order);
  if (auto focal_35mm = ReadInteger(
          FindEntry(exif.get(), EXIF_IFD_EXIF, EXIF_TAG_FOCAL_LENGTH_IN_35MM_FILM), order)) {
    info.focal_length_35mm = static_cast<double>(*focal_35mm);
  }
  if (auto resolution = ReadRational(
          FindEntry(exif.get(), EXIF_IFD_EXIF, EXIF_TAG_FOCAL_PLANE_X_RESOLUTION), order)) {
    const int64_t unit =
        ReadInteger(FindEntry(exif.get(), EXIF_IFD_EXIF, EXIF_TAG_FOCAL_PLANE_RESOLUTION_UNIT),
                    order)
            .value_or(2);
    const double mm_per_unit = MillimetresPerUnit(unit);
    if (mm_per_unit > 0 && *resolution > 0 && std::isfinite(*resolution)) {
      info.focal_plane_x_resolution = *resolution / mm_per_unit;
    }
  }
  const auto read_dimension = [&](ExifTag tag) -> std::optional<int> {
    const auto value = ReadInteger(FindEntry(exif.get(), EXIF_IFD_EXIF, tag), order);
    if (!value || *value <= 0 || *value > INT_MAX) return std::nullopt;
    return static_cast<int>(*value);
  };
  info.pixel_x_dimension = read_dimension(EXIF_TAG_PIXEL_X_DIMENSION);
  info.pixel_y_dimension = read_dimension(EXIF_TAG_PIXEL_Y_DIMENSION);
  return info;
}

}  // namespace tessera
