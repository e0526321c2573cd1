#include "image/sensor_database.h"

#include <cctype>
#include <iterator>

namespace tessera {
namespace {

// Lower case, whitespace runs made one space, trimmed.
std::string Normalize(const std::string& text) {
  std::string normalized;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (std::isspace(u)) {
      if (!normalized.empty() && normalized.back() != ' ') normalized += ' ';
    } else {
      normalized += static_cast<char>(std::tolower(u));
    }
  }
  if (!normalized.empty() && normalized.back() == ' ') normalized.pop_back();
  return normalized;
}

bool StartsWith(const std::string& text, const std::string& prefix) {
  return text.compare(0, prefix.size(), prefix) == 0;
}

bool EndsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Whether `brand` is a whole word of the (normalized) make, so that
// "eastman kodak company" and "olympus imaging corp." name their brands.
bool MakeNamesBrand(const std::string& make, const std::string& brand) {
  for (size_t pos = make.find(brand); pos != std::string::npos; pos = make.find(brand, pos + 1)) {
    const size_t end = pos + brand.size();
    const bool starts_word = pos == 0 || !std::isalnum(static_cast<unsigned char>(make[pos - 1]));
    const bool ends_word =
        end == make.size() || !std::isalnum(static_cast<unsigned char>(make[end]));
    if (starts_word && ends_word) return true;
  }
  return false;
}

// The model without the brand in front and without generic trailing words.
std::string CanonicalModel(std::string model, const std::string& brand) {
  if (StartsWith(model, brand + " ")) model.erase(0, brand.size() + 1);
  for (bool changed = true; changed;) {
    changed = false;
    for (const std::string suffix : {" digital camera", " camera", " zoom"}) {
      if (EndsWith(model, suffix) && model.size() > suffix.size()) {
        model.erase(model.size() - suffix.size());
        changed = true;
      }
    }
  }
  return model;
}

// The table itself: constant data of trivially destructible entries, so it needs no
// initialization at run time.
constexpr SensorEntry kSensorTable[] = {
    // Canon full frame.
    {"canon", "EOS-1D X", 36.0},
    {"canon", "EOS-1Ds Mark III", 36.0},
    {"canon", "EOS 5D", 35.8},
    {"canon", "EOS 5D Mark II", 36.0},
    {"canon", "EOS 5D Mark III", 36.0},
    {"canon", "EOS 5D Mark IV", 36.0},
    {"canon", "EOS 5DS", 36.0},
    {"canon", "EOS 5DS R", 36.0},
    {"canon", "EOS 6D", 35.8},
    {"canon", "EOS 6D Mark II", 35.9},
    {"canon", "EOS R", 36.0},
    {"canon", "EOS RP", 35.9},
    {"canon", "EOS R5", 36.0},
    {"canon", "EOS R6", 35.9},
    // Canon APS-C.
    {"canon", "EOS 7D", 22.3},
    {"canon", "EOS 7D Mark II", 22.4},
    {"canon", "EOS 40D", 22.2},
    {"canon", "EOS 50D", 22.3},
    {"canon", "EOS 60D", 22.3},
    {"canon", "EOS 70D", 22.5},
    {"canon", "EOS 80D", 22.3},
    {"canon", "EOS 90D", 22.3},
    {"canon", "EOS 400D DIGITAL", 22.2},
    {"canon", "EOS 450D", 22.2},
    {"canon", "EOS 500D", 22.3},
    {"canon", "EOS 550D", 22.3},
    {"canon", "EOS 600D", 22.3},
    {"canon", "EOS REBEL T3i", 22.3},
    {"canon", "EOS 650D", 22.3},
    {"canon", "EOS 700D", 22.3},
    {"canon", "EOS REBEL T5i", 22.3},
    {"canon", "EOS 750D", 22.3},
    {"canon", "EOS 1100D", 22.2},
    {"canon", "EOS 1200D", 22.3},
    {"canon", "EOS M50", 22.3},
    // Canon compacts.
    {"canon", "PowerShot G9", 7.44},
    {"canon", "PowerShot G12", 7.44},
    {"canon", "PowerShot S95", 7.44},
    {"canon", "PowerShot S100", 7.44},
    {"canon", "PowerShot G7 X", 13.2},
    {"canon", "PowerShot G9 X", 13.2},
    {"canon", "PowerShot SX260 HS", 6.17},
    {"canon", "PowerShot SX280 HS", 6.17},
    // Nikon FX.
    {"nikon", "D3", 36.0},
    {"nikon", "D3X", 35.9},
    {"nikon", "D4", 36.0},
    {"nikon", "D700", 36.0},
    {"nikon", "D600", 35.9},
    {"nikon", "D610", 35.9},
    {"nikon", "D750", 35.9},
    {"nikon", "D800", 35.9},
    {"nikon", "D800E", 35.9},
    {"nikon", "D810", 35.9},
    {"nikon", "D850", 35.9},
    {"nikon", "Z 5", 35.9},
    {"nikon", "Z 6", 35.9},
    {"nikon", "Z 7", 35.9},
    // Nikon DX.
    {"nikon", "D90", 23.6},
    {"nikon", "D300", 23.6},
    {"nikon", "D300S", 23.6},
    {"nikon", "D500", 23.5},
    {"nikon", "D3100", 23.1},
    {"nikon", "D3200", 23.2},
    {"nikon", "D3300", 23.5},
    {"nikon", "D3400", 23.5},
    {"nikon", "D5100", 23.6},
    {"nikon", "D5200", 23.5},
    {"nikon", "D5300", 23.5},
    {"nikon", "D7000", 23.6},
    {"nikon", "D7100", 23.5},
    {"nikon", "D7200", 23.5},
    {"nikon", "D7500", 23.5},
    {"nikon", "Z 50", 23.5},
    // Sony.
    {"sony", "ILCE-7", 35.8},
    {"sony", "ILCE-7R", 35.9},
    {"sony", "ILCE-7M2", 35.8},
    {"sony", "ILCE-7RM2", 35.9},
    {"sony", "ILCE-7M3", 35.6},
    {"sony", "ILCE-7RM3", 35.9},
    {"sony", "ILCE-9", 35.6},
    {"sony", "DSC-RX1", 35.8},
    {"sony", "ILCE-5100", 23.5},
    {"sony", "ILCE-6000", 23.5},
    {"sony", "ILCE-6300", 23.5},
    {"sony", "ILCE-6500", 23.5},
    {"sony", "NEX-5N", 23.4},
    {"sony", "NEX-7", 23.5},
    {"sony", "DSC-RX100", 13.2},
    {"sony", "DSC-RX100M2", 13.2},
    {"sony", "DSC-RX100M3", 13.2},
    {"sony", "DSC-RX100M4", 13.2},
    {"sony", "DSC-RX100M5", 13.2},
    // Apple (newer phones write a reliable 35 mm equivalent).
    {"apple", "iPhone 4", 4.54},
    {"apple", "iPhone 4S", 4.54},
    {"apple", "iPhone 5", 4.54},
    {"apple", "iPhone 5s", 4.89},
    {"apple", "iPhone 6", 4.89},
    {"apple", "iPhone 6 Plus", 4.89},
    // GoPro (1/2.3").
    {"gopro", "HERO4 Black", 6.17},
    {"gopro", "HERO4 Silver", 6.17},
    {"gopro", "HERO5 Black", 6.17},
    {"gopro", "HERO6 Black", 6.17},
    {"gopro", "HERO7 Black", 6.17},
    // DJI drone cameras.
    {"dji", "FC300S", 6.17},  // Phantom 3 Advanced
    {"dji", "FC300X", 6.17},  // Phantom 3 Professional
    {"dji", "FC330", 6.17},   // Phantom 4
    {"dji", "FC220", 6.17},   // Mavic Pro
    {"dji", "FC2103", 6.17},  // Mavic Air
    {"dji", "FC7203", 6.17},  // Mavic Mini
    {"dji", "FC6310", 13.2},  // Phantom 4 Pro
    {"dji", "FC6310S", 13.2},
    {"dji", "L1D-20c", 13.2},  // Mavic 2 Pro
    {"dji", "FC6520", 17.3},   // Zenmuse X5S
    // Fujifilm.
    {"fujifilm", "X-T1", 23.6},
    {"fujifilm", "X-T2", 23.6},
    {"fujifilm", "X-T3", 23.5},
    {"fujifilm", "X-T20", 23.5},
    {"fujifilm", "X-E2", 23.6},
    {"fujifilm", "X-Pro2", 23.6},
    {"fujifilm", "X100F", 23.5},
    // Panasonic and Olympus (Four Thirds: 17.3 mm).
    {"panasonic", "DMC-GH3", 17.3},
    {"panasonic", "DMC-GH4", 17.3},
    {"panasonic", "DC-GH5", 17.3},
    {"panasonic", "DMC-G7", 17.3},
    {"panasonic", "DMC-GX7", 17.3},
    {"panasonic", "DMC-GX8", 17.3},
    {"panasonic", "DMC-FZ1000", 13.2},
    {"panasonic", "DMC-ZS100", 13.2},
    {"olympus", "E-M5", 17.3},
    {"olympus", "E-M5MarkII", 17.3},
    {"olympus", "E-M10", 17.3},
    {"olympus", "E-M1", 17.3},
    {"olympus", "E-M1MarkII", 17.3},
    {"olympus", "E-PL5", 17.3},
    {"olympus", "TG-5", 6.17},
    // Pentax and Ricoh.
    {"pentax", "K-5", 23.7},
    {"pentax", "K-5 II", 23.7},
    {"pentax", "K-3", 23.5},
    {"pentax", "K-1", 35.9},
    {"ricoh", "GR", 23.7},
    {"ricoh", "GR II", 23.7},
    // Others.
    {"samsung", "NX300", 23.5},
    {"leica", "M9", 35.8},
    {"casio", "EX-Z750", 7.18},
    // Kodak compacts (1/2.5").
    {"kodak", "Z612", 5.75},
    {"kodak", "Z650", 5.75},
    {"kodak", "Z740", 5.75},
};

}  // namespace

const std::vector<SensorEntry>& SensorDatabase() {
  static const std::vector<SensorEntry> kEntries(std::begin(kSensorTable), std::end(kSensorTable));
  return kEntries;
}

std::optional<double> LookupSensorWidthMm(const std::string& make, const std::string& model) {
  const std::string normalized_make = Normalize(make);
  const std::string normalized_model = Normalize(model);
  if (normalized_model.empty()) return std::nullopt;
  for (const SensorEntry& entry : SensorDatabase()) {
    const std::string brand = entry.make;
    // Pentax bodies say "RICOH IMAGING COMPANY, LTD." as make and "PENTAX K-1" as model.
    if (!MakeNamesBrand(normalized_make, brand) && !StartsWith(normalized_model, brand + " ")) {
      continue;
    }
    if (CanonicalModel(normalized_model, brand) == CanonicalModel(Normalize(entry.model), brand)) {
      return entry.width_mm;
    }
  }
  return std::nullopt;
}

}  // namespace tessera
