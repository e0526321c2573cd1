#include "tessera/io/exif.h"

#include <libexif/exif-data.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace tessera {
namespace {

// libexif defines the GPS tags as plain integers.
constexpr ExifTag kGpsLatitudeRef = static_cast<ExifTag>(EXIF_TAG_GPS_LATITUDE_REF);
constexpr ExifTag kGpsLatitude = static_cast<ExifTag>(EXIF_TAG_GPS_LATITUDE);
constexpr ExifTag kGpsLongitudeRef = static_cast<ExifTag>(EXIF_TAG_GPS_LONGITUDE_REF);
constexpr ExifTag kGpsLongitude = static_cast<ExifTag>(EXIF_TAG_GPS_LONGITUDE);
constexpr ExifTag kGpsAltitudeRef = static_cast<ExifTag>(EXIF_TAG_GPS_ALTITUDE_REF);
constexpr ExifTag kGpsAltitude = static_cast<ExifTag>(EXIF_TAG_GPS_ALTITUDE);

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

// A rational component of `entry`, checked to be finite (a zero denominator is not).
std::optional<double> RationalAt(const ExifEntry* entry, unsigned long index, ExifByteOrder order) {
  const size_t size = exif_format_get_size(EXIF_FORMAT_RATIONAL);
  const ExifRational value = exif_get_rational(entry->data + index * size, order);
  if (value.denominator == 0) return std::nullopt;
  return static_cast<double>(value.numerator) / value.denominator;
}

// "GPSLatitude" etc. for messages.
std::string GpsTagName(ExifTag tag) {
  const char* name = exif_tag_get_name_in_ifd(tag, EXIF_IFD_GPS);
  return name != nullptr ? name : "GPS tag " + std::to_string(static_cast<int>(tag));
}

// Degrees from a GPSLatitude/GPSLongitude entry (3 RATIONALs: degrees, minutes,
// seconds) and its Ref ('N'/'S' or 'E'/'W'). Returns the problem, or "" with *degrees.
std::string ReadGpsAngle(ExifContent* gps, ExifTag tag, ExifTag ref_tag, char positive,
                         char negative, double max_degrees, ExifByteOrder order, double* degrees) {
  const std::string name = GpsTagName(tag);
  const ExifEntry* entry = exif_content_get_entry(gps, tag);
  if (entry == nullptr) return name + " is missing";
  if (entry->format != EXIF_FORMAT_RATIONAL) {
    return name + " has format " + exif_format_get_name(entry->format) + ", expected Rational";
  }
  if (entry->components != 3 || entry->data == nullptr ||
      entry->size < 3 * exif_format_get_size(EXIF_FORMAT_RATIONAL)) {
    return name + " has " + std::to_string(entry->components) + " components, expected 3";
  }
  double parts[3];
  for (unsigned long i = 0; i < 3; ++i) {
    const auto part = RationalAt(entry, i, order);
    if (!part) return name + " has a zero denominator";
    parts[i] = *part;
  }
  if (parts[1] >= 60 || parts[2] >= 60) {
    return name + " has minutes or seconds of 60 or more";
  }
  const double value = parts[0] + parts[1] / 60 + parts[2] / 3600;
  if (!std::isfinite(value) || value > max_degrees) {
    return name + " is out of range (" + std::to_string(value) + " degrees)";
  }
  const std::string ref_name = GpsTagName(ref_tag);
  ExifEntry* ref = exif_content_get_entry(gps, ref_tag);
  if (ref == nullptr) return ref_name + " is missing";
  const std::string ref_text = ReadAscii(ref);
  if (ref->format != EXIF_FORMAT_ASCII || ref_text.size() != 1 ||
      (std::toupper(static_cast<unsigned char>(ref_text[0])) != positive &&
       std::toupper(static_cast<unsigned char>(ref_text[0])) != negative)) {
    return ref_name + " is '" + ref_text + "', expected '" + positive + "' or '" + negative + "'";
  }
  *degrees = std::toupper(static_cast<unsigned char>(ref_text[0])) == negative ? -value : value;
  return "";
}

// The GPS fix of the GPS IFD; nullopt without one (no warning) or when a tag is
// malformed (a warning in *warnings).
std::optional<GpsPosition> ReadGps(ExifData* data, ExifByteOrder order,
                                   std::vector<std::string>* warnings) {
  ExifContent* gps = data->ifd[EXIF_IFD_GPS];
  if (gps == nullptr || (exif_content_get_entry(gps, kGpsLatitude) == nullptr &&
                         exif_content_get_entry(gps, kGpsLongitude) == nullptr)) {
    return std::nullopt;
  }
  GpsPosition position;
  std::string problem =
      ReadGpsAngle(gps, kGpsLatitude, kGpsLatitudeRef, 'N', 'S', 90, order, &position.latitude_deg);
  if (problem.empty()) {
    problem = ReadGpsAngle(gps, kGpsLongitude, kGpsLongitudeRef, 'E', 'W', 180, order,
                           &position.longitude_deg);
  }
  if (problem.empty()) {
    if (const ExifEntry* altitude = exif_content_get_entry(gps, kGpsAltitude)) {
      std::optional<double> value;
      if (altitude->format != EXIF_FORMAT_RATIONAL || altitude->components != 1 ||
          altitude->data == nullptr ||
          altitude->size < exif_format_get_size(EXIF_FORMAT_RATIONAL)) {
        problem = "GPSAltitude is not one Rational";
      } else if (!(value = RationalAt(altitude, 0, order))) {
        problem = "GPSAltitude has a zero denominator";
      } else {
        // GPSAltitudeRef: 0 above sea level (also when absent), 1 below.
        int64_t ref = 0;
        const ExifEntry* ref_entry = exif_content_get_entry(gps, kGpsAltitudeRef);
        if (ref_entry != nullptr) {
          if (!HasComponent(ref_entry, EXIF_FORMAT_BYTE)) {
            problem = "GPSAltitudeRef is not a Byte";
          } else {
            ref = ref_entry->data[0];
            if (ref != 0 && ref != 1) {
              problem = "GPSAltitudeRef is " + std::to_string(ref) + ", expected 0 or 1";
            }
          }
        }
        if (problem.empty()) position.altitude_m = ref == 1 ? -*value : *value;
      }
    }
  }
  if (!problem.empty()) {
    warnings->push_back("GPS ignored: " + problem);
    return std::nullopt;
  }
  return position;
}

// Days from 1970-01-01 to a proleptic Gregorian date (H. Hinnant's days_from_civil).
int64_t DaysFromCivil(int64_t year, int64_t month, int64_t day) {
  year -= month <= 2;
  const int64_t era = (year >= 0 ? year : year - 399) / 400;
  const int64_t year_of_era = year - era * 400;
  const int64_t day_of_year = (153 * (month + (month > 2 ? -3 : 9)) + 2) / 5 + day - 1;
  const int64_t day_of_era = year_of_era * 365 + year_of_era / 4 - year_of_era / 100 + day_of_year;
  return era * 146097 + day_of_era - 719468;
}

}  // namespace

std::optional<double> ParseExifDateTime(const std::string& date_time, const std::string& subsec) {
  // "YYYY:MM:DD HH:MM:SS", 19 characters (the NUL is not part of the text).
  if (date_time.size() != 19) return std::nullopt;
  const char* pattern = "dddd:dd:dd dd:dd:dd";
  for (size_t i = 0; i < 19; ++i) {
    const bool digit = std::isdigit(static_cast<unsigned char>(date_time[i])) != 0;
    if (pattern[i] == 'd' ? !digit : date_time[i] != pattern[i]) return std::nullopt;
  }
  const auto number = [&](size_t begin, size_t length) {
    return std::stoll(date_time.substr(begin, length));
  };
  const int64_t year = number(0, 4), month = number(5, 2), day = number(8, 2);
  const int64_t hour = number(11, 2), minute = number(14, 2), second = number(17, 2);
  static constexpr int kDaysInMonth[] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (year < 1 || month < 1 || month > 12 || day < 1 || day > kDaysInMonth[month - 1] ||
      hour > 23 || minute > 59 || second > 60) {
    return std::nullopt;
  }
  double seconds = static_cast<double>(DaysFromCivil(year, month, day) * 86400 + hour * 3600 +
                                       minute * 60 + second);
  // SubSecTime: the decimal digits after the point; anything else is ignored.
  size_t digits = 0;
  while (digits < subsec.size() && std::isdigit(static_cast<unsigned char>(subsec[digits]))) {
    ++digits;
  }
  if (digits > 0 && digits <= 9) seconds += std::stod("0." + subsec.substr(0, digits));
  return seconds;
}

ImageMetadata MetadataFromExif(const ExifInfo& exif) {
  ImageMetadata metadata;
  metadata.make = exif.make;
  metadata.model = exif.model;
  metadata.focal_length_mm = exif.focal_length_mm;
  metadata.focal_length_35mm = exif.focal_length_35mm;
  metadata.gps = exif.gps;
  metadata.capture_time_s = exif.capture_time_s;
  return metadata;
}

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

  info.gps = ReadGps(exif.get(), order, &info.warnings);
  const std::string date_time =
      ReadAscii(FindEntry(exif.get(), EXIF_IFD_EXIF, EXIF_TAG_DATE_TIME_ORIGINAL));
  // Cameras without a clock write blanks or zeros ("    :  :     :  :  "): no date, no warning.
  const bool blank = date_time.find_first_not_of(" :0") == std::string::npos;
  if (!blank) {
    info.capture_time_s = ParseExifDateTime(
        date_time, ReadAscii(FindEntry(exif.get(), EXIF_IFD_EXIF, EXIF_TAG_SUB_SEC_TIME_ORIGINAL)));
    if (!info.capture_time_s) {
      info.warnings.push_back("DateTimeOriginal ignored: '" + date_time +
                              "' is not a date 'YYYY:MM:DD HH:MM:SS'");
    }
  }
  return info;
}

}  // namespace tessera
