// geotag_images IMAGE_DIR POSITIONS LATITUDE LONGITUDE ALTITUDE [options]
// Writes EXIF GPS tags (GPSLatitude/Ref, GPSLongitude/Ref, GPSAltitude/Ref, with libexif)
// into the JPEG files of IMAGE_DIR, in place, keeping their other EXIF tags. Each image's
// position comes from POSITIONS: a folder of Strecha-style ground-truth files
// NAME.camera (the camera centre on line 8, as in fountain-P11/gt), or a text file of
// lines "NAME x y z". Positions are metres in a local frame taken as east (x), north (y)
// and up (z) about the origin LATITUDE LONGITUDE (degrees, WGS84) ALTITUDE (metres);
// metres become degrees with the ellipsoid's radii of curvature at the origin.
// Options:
//   --noise M           adds Gaussian noise of M metres (standard deviation) to x and y
//   --altitude-noise M  and of M metres to z
//   --seed N            seeds the noise (default 0)
//   --skip NAME         leaves NAME untagged (repeatable)
//   --no-altitude       writes no GPSAltitude tags
//   --tag NAME=LAT,LON,ALT  writes these WGS84 values for NAME instead (repeatable):
//                       the tags of a camera without a fix (0,0,0), or a broken one
// Prints "NAME latitude longitude altitude" per tagged image. Exit 2 on bad input.
// For end-to-end tests and benchmarks of GPS-based pair selection.

#include <libexif/exif-data.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

// libexif defines the GPS tags as plain integers.
constexpr ExifTag kGpsVersionId = static_cast<ExifTag>(EXIF_TAG_GPS_VERSION_ID);
constexpr ExifTag kGpsLatitudeRef = static_cast<ExifTag>(EXIF_TAG_GPS_LATITUDE_REF);
constexpr ExifTag kGpsLatitude = static_cast<ExifTag>(EXIF_TAG_GPS_LATITUDE);
constexpr ExifTag kGpsLongitudeRef = static_cast<ExifTag>(EXIF_TAG_GPS_LONGITUDE_REF);
constexpr ExifTag kGpsLongitude = static_cast<ExifTag>(EXIF_TAG_GPS_LONGITUDE);
constexpr ExifTag kGpsAltitudeRef = static_cast<ExifTag>(EXIF_TAG_GPS_ALTITUDE_REF);
constexpr ExifTag kGpsAltitude = static_cast<ExifTag>(EXIF_TAG_GPS_ALTITUDE);

constexpr double kPi = 3.14159265358979323846;

struct Failure {
  std::string message;
};

std::map<std::string, std::array<double, 3>> ReadPositions(const fs::path& source) {
  std::map<std::string, std::array<double, 3>> positions;
  if (fs::is_directory(source)) {
    for (const auto& entry : fs::directory_iterator(source)) {
      const std::string file = entry.path().filename().string();
      const std::string suffix = ".camera";
      if (file.size() <= suffix.size() || file.substr(file.size() - suffix.size()) != suffix) {
        continue;
      }
      std::ifstream stream(entry.path());
      std::string line;
      for (int i = 0; i < 8 && std::getline(stream, line); ++i) {
      }
      std::istringstream centre(line);
      std::array<double, 3> c{};
      if (!(centre >> c[0] >> c[1] >> c[2])) {
        throw Failure{entry.path().string() + ": line 8 is not a camera centre 'x y z'"};
      }
      positions[file.substr(0, file.size() - suffix.size())] = c;
    }
  } else {
    std::ifstream stream(source);
    if (!stream) throw Failure{source.string() + ": cannot read"};
    std::string line;
    for (int number = 1; std::getline(stream, line); ++number) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream fields(line);
      std::string name;
      std::array<double, 3> p{};
      if (!(fields >> name >> p[0] >> p[1] >> p[2])) {
        throw Failure{source.string() + ":" + std::to_string(number) + ": expected 'NAME x y z'"};
      }
      positions[name] = p;
    }
  }
  if (positions.empty()) throw Failure{source.string() + ": no positions"};
  return positions;
}

using Bytes = std::vector<unsigned char>;

// The JPEG's segments before the scan, as (marker, payload); `rest` is everything from
// the SOS marker on.
struct Jpeg {
  std::vector<std::pair<unsigned char, Bytes>> segments;
  Bytes rest;
};

Jpeg ParseJpeg(const Bytes& bytes, const std::string& name) {
  if (bytes.size() < 4 || bytes[0] != 0xff || bytes[1] != 0xd8)
    throw Failure{name + ": not a JPEG"};
  Jpeg jpeg;
  size_t pos = 2;
  while (pos + 4 <= bytes.size()) {
    if (bytes[pos] != 0xff) throw Failure{name + ": damaged JPEG segment"};
    const unsigned char marker = bytes[pos + 1];
    if (marker == 0xda) break;  // start of scan
    const size_t length = (bytes[pos + 2] << 8) | bytes[pos + 3];
    if (length < 2 || pos + 2 + length > bytes.size()) throw Failure{name + ": truncated JPEG"};
    jpeg.segments.emplace_back(marker,
                               Bytes(bytes.begin() + pos + 4, bytes.begin() + pos + 2 + length));
    pos += 2 + length;
  }
  jpeg.rest.assign(bytes.begin() + pos, bytes.end());
  return jpeg;
}

bool IsExif(const std::pair<unsigned char, Bytes>& segment) {
  return segment.first == 0xe1 && segment.second.size() >= 6 &&
         std::memcmp(segment.second.data(), "Exif\0\0", 6) == 0;
}

void SetEntry(ExifData* data, ExifTag tag, ExifFormat format, unsigned long components,
              const std::function<void(unsigned char*)>& fill) {
  ExifContent* gps = data->ifd[EXIF_IFD_GPS];
  if (ExifEntry* old = exif_content_get_entry(gps, tag)) exif_content_remove_entry(gps, old);
  ExifMem* mem = exif_mem_new_default();
  ExifEntry* entry = exif_entry_new_mem(mem);
  const unsigned int size = exif_format_get_size(format) * components;
  entry->data = static_cast<unsigned char*>(exif_mem_alloc(mem, size));
  entry->size = size;
  entry->tag = tag;
  entry->format = format;
  entry->components = components;
  fill(entry->data);
  exif_content_add_entry(gps, entry);
  exif_mem_unref(mem);
  exif_entry_unref(entry);
}

// Degrees as degrees, minutes and seconds with 1/10000 s resolution (3 mm).
void SetAngle(ExifData* data, ExifByteOrder order, ExifTag tag, ExifTag ref_tag, double degrees,
              char positive, char negative) {
  const double magnitude = std::abs(degrees);
  const auto whole = static_cast<ExifLong>(magnitude);
  const double minutes_real = (magnitude - whole) * 60;
  const auto minutes = static_cast<ExifLong>(minutes_real);
  const auto seconds = static_cast<ExifLong>(std::llround((minutes_real - minutes) * 60 * 10000));
  SetEntry(data, tag, EXIF_FORMAT_RATIONAL, 3, [&](unsigned char* p) {
    exif_set_rational(p, order, {whole, 1});
    exif_set_rational(p + 8, order, {minutes, 1});
    exif_set_rational(p + 16, order, {seconds, 10000});
  });
  SetEntry(data, ref_tag, EXIF_FORMAT_ASCII, 2, [&](unsigned char* p) {
    p[0] = static_cast<unsigned char>(degrees < 0 ? negative : positive);
    p[1] = 0;
  });
}

void Geotag(const fs::path& file, double latitude, double longitude,
            const std::optional<double>& altitude) {
  std::ifstream in(file, std::ios::binary);
  const Bytes bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Jpeg jpeg = ParseJpeg(bytes, file.string());

  ExifData* data = exif_data_new();
  exif_data_unset_option(data, EXIF_DATA_OPTION_FOLLOW_SPECIFICATION);
  exif_data_set_byte_order(data, EXIF_BYTE_ORDER_INTEL);
  for (const auto& segment : jpeg.segments) {
    if (IsExif(segment)) {
      exif_data_load_data(data, segment.second.data(),
                          static_cast<unsigned int>(segment.second.size()));
      break;
    }
  }
  const ExifByteOrder order = exif_data_get_byte_order(data);
  SetEntry(data, kGpsVersionId, EXIF_FORMAT_BYTE, 4, [](unsigned char* p) {
    p[0] = 2;
    p[1] = 3;
    p[2] = p[3] = 0;
  });
  SetAngle(data, order, kGpsLatitude, kGpsLatitudeRef, latitude, 'N', 'S');
  SetAngle(data, order, kGpsLongitude, kGpsLongitudeRef, longitude, 'E', 'W');
  if (altitude) {
    SetEntry(data, kGpsAltitudeRef, EXIF_FORMAT_BYTE, 1,
             [&](unsigned char* p) { p[0] = *altitude < 0 ? 1 : 0; });
    SetEntry(data, kGpsAltitude, EXIF_FORMAT_RATIONAL, 1, [&](unsigned char* p) {
      // Millimetres where they fit the 32-bit numerator, else metres (an altitude of
      // -1e9 m, as a broken camera writes).
      const ExifLong denominator = std::abs(*altitude) * 1000 < 4e9 ? 1000 : 1;
      exif_set_rational(
          p, order,
          {static_cast<ExifLong>(std::llround(std::abs(*altitude) * denominator)), denominator});
    });
  }
  unsigned char* buffer = nullptr;
  unsigned int size = 0;
  exif_data_save_data(data, &buffer, &size);
  exif_data_unref(data);
  if (buffer == nullptr || size + 2 > 0xffff) {
    std::free(buffer);
    throw Failure{file.string() + ": cannot write the EXIF block"};
  }
  const Bytes block(buffer, buffer + size);
  std::free(buffer);

  Bytes out = {0xff, 0xd8};
  const auto put_segment = [&out](unsigned char marker, const Bytes& payload) {
    const size_t length = payload.size() + 2;
    out.insert(out.end(), {0xff, marker, static_cast<unsigned char>(length >> 8),
                           static_cast<unsigned char>(length & 0xff)});
    out.insert(out.end(), payload.begin(), payload.end());
  };
  // EXIF first, as cameras write it (after a JFIF APP0 when there is one).
  size_t k = 0;
  if (!jpeg.segments.empty() && jpeg.segments[0].first == 0xe0)
    put_segment(0xe0, jpeg.segments[k++].second);
  put_segment(0xe1, block);
  for (; k < jpeg.segments.size(); ++k) {
    if (!IsExif(jpeg.segments[k])) put_segment(jpeg.segments[k].first, jpeg.segments[k].second);
  }
  out.insert(out.end(), jpeg.rest.begin(), jpeg.rest.end());
  const fs::path temporary = file.string() + ".geotag-tmp";
  std::ofstream(temporary, std::ios::binary)
      .write(reinterpret_cast<const char*>(out.data()), static_cast<std::streamsize>(out.size()));
  fs::rename(temporary, file);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 6) {
    std::cerr << "usage: geotag_images IMAGE_DIR POSITIONS LATITUDE LONGITUDE ALTITUDE "
                 "[--noise M] [--altitude-noise M] [--seed N] [--skip NAME]... [--no-altitude]\n"
                 "       [--tag NAME=LAT,LON,ALT]...\n";
    return 2;
  }
  try {
    const fs::path image_dir(argv[1]);
    const auto positions = ReadPositions(argv[2]);
    const double latitude0 = std::stod(argv[3]), longitude0 = std::stod(argv[4]);
    const double altitude0 = std::stod(argv[5]);
    double noise = 0, altitude_noise = 0;
    unsigned seed = 0;
    bool with_altitude = true;
    std::set<std::string> skip;
    std::map<std::string, std::array<double, 3>> fixed;
    for (int i = 6; i < argc; ++i) {
      const std::string flag = argv[i];
      const auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw Failure{flag + ": missing value"};
        return argv[++i];
      };
      if (flag == "--noise") {
        noise = std::stod(value());
      } else if (flag == "--altitude-noise") {
        altitude_noise = std::stod(value());
      } else if (flag == "--seed") {
        seed = static_cast<unsigned>(std::stoul(value()));
      } else if (flag == "--skip") {
        skip.insert(value());
      } else if (flag == "--tag") {
        const std::string tag = value();
        const size_t equals = tag.find('=');
        std::array<double, 3> wgs84{};
        char tail = 0;
        if (equals == std::string::npos ||
            std::sscanf(tag.c_str() + equals + 1, "%lf,%lf,%lf%c", &wgs84[0], &wgs84[1], &wgs84[2],
                        &tail) != 3) {
          throw Failure{"--tag: expected NAME=LAT,LON,ALT, got '" + tag + "'"};
        }
        fixed[tag.substr(0, equals)] = wgs84;
      } else if (flag == "--no-altitude") {
        with_altitude = false;
      } else {
        throw Failure{flag + ": unknown option"};
      }
    }
    constexpr double kA = 6378137.0, kE2 = 6.69437999014e-3;
    const double phi = latitude0 * kPi / 180;
    const double w = 1 - kE2 * std::sin(phi) * std::sin(phi);
    const double meridian = kA * (1 - kE2) / std::pow(w, 1.5), normal = kA / std::sqrt(w);
    std::mt19937 rng(seed);
    std::normal_distribution<double> gaussian(0, 1);
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(image_dir)) {
      const std::string extension = entry.path().extension().string();
      if (entry.is_regular_file() && (extension == ".jpg" || extension == ".JPG" ||
                                      extension == ".jpeg" || extension == ".JPEG")) {
        files.push_back(entry.path());
      }
    }
    std::sort(files.begin(), files.end());
    for (const fs::path& file : files) {
      const std::string name = file.filename().string();
      // Draw the noise for every image, skipped or not: the others' positions do not
      // depend on which are skipped.
      const double east_noise = noise * gaussian(rng), north_noise = noise * gaussian(rng);
      const double up_noise = altitude_noise * gaussian(rng);
      if (skip.count(name) > 0) continue;
      if (const auto tag = fixed.find(name); tag != fixed.end()) {
        const auto& [latitude, longitude, altitude] = tag->second;
        Geotag(file, latitude, longitude, altitude);
        std::cout << name << std::setprecision(10) << " " << latitude << " " << longitude << " "
                  << altitude << "\n";
        continue;
      }
      const auto it = positions.find(name);
      if (it == positions.end()) throw Failure{name + ": no position in " + std::string(argv[2])};
      const double east = it->second[0] + east_noise, north = it->second[1] + north_noise;
      const double latitude = latitude0 + north / meridian * 180 / kPi;
      const double longitude = longitude0 + east / (normal * std::cos(phi)) * 180 / kPi;
      std::optional<double> altitude;
      if (with_altitude) altitude = altitude0 + it->second[2] + up_noise;
      Geotag(file, latitude, longitude, altitude);
      std::cout << name << std::setprecision(10) << " " << latitude << " " << longitude << " "
                << (altitude ? std::to_string(*altitude) : "-") << "\n";
    }
  } catch (const Failure& failure) {
    std::cerr << "geotag_images: " << failure.message << "\n";
    return 2;
  } catch (const std::exception& error) {
    std::cerr << "geotag_images: " << error.what() << "\n";
    return 2;
  }
  return 0;
}
