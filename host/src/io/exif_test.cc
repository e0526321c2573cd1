#include "tessera/io/exif.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "test_image_files.h"

namespace tessera {
namespace {

// libexif defines the GPS tags as plain integers.
constexpr ExifTag kGpsLatitudeRef = static_cast<ExifTag>(EXIF_TAG_GPS_LATITUDE_REF);
constexpr ExifTag kGpsLatitude = static_cast<ExifTag>(EXIF_TAG_GPS_LATITUDE);
constexpr ExifTag kGpsLongitudeRef = static_cast<ExifTag>(EXIF_TAG_GPS_LONGITUDE_REF);
constexpr ExifTag kGpsLongitude = static_cast<ExifTag>(EXIF_TAG_GPS_LONGITUDE);
constexpr ExifTag kGpsAltitudeRef = static_cast<ExifTag>(EXIF_TAG_GPS_ALTITUDE_REF);
constexpr ExifTag kGpsAltitude = static_cast<ExifTag>(EXIF_TAG_GPS_ALTITUDE);

// One rational per value, each as numerator / denominator.
struct Rational {
  ExifLong numerator, denominator;
};

void AddRationals(ExifData* data, ExifByteOrder order, ExifTag tag,
                  const std::vector<Rational>& values, ExifFormat format = EXIF_FORMAT_RATIONAL) {
  ExifEntry* entry = testing::AddExifEntry(data, EXIF_IFD_GPS, tag, format, values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    exif_set_rational(entry->data + 8 * i, order, {values[i].numerator, values[i].denominator});
  }
}

void AddAscii(ExifData* data, ExifIfd ifd, ExifTag tag, const std::string& text) {
  ExifEntry* entry = testing::AddExifEntry(data, ifd, tag, EXIF_FORMAT_ASCII, text.size() + 1);
  std::copy(text.begin(), text.end(), entry->data);
  entry->data[text.size()] = 0;
}

void AddByte(ExifData* data, ExifTag tag, unsigned char value) {
  ExifEntry* entry = testing::AddExifEntry(data, EXIF_IFD_GPS, tag, EXIF_FORMAT_BYTE, 1);
  entry->data[0] = value;
}

// 48 deg 51' 29.5" N, 2 deg 17' 40.2" E, 35.25 m: the Eiffel tower's foot.
void AddGoodGps(ExifData* data, ExifByteOrder order) {
  AddAscii(data, EXIF_IFD_GPS, kGpsLatitudeRef, "N");
  AddRationals(data, order, kGpsLatitude, {{48, 1}, {51, 1}, {295, 10}});
  AddAscii(data, EXIF_IFD_GPS, kGpsLongitudeRef, "E");
  AddRationals(data, order, kGpsLongitude, {{2, 1}, {17, 1}, {402, 10}});
  AddByte(data, kGpsAltitudeRef, 0);
  AddRationals(data, order, kGpsAltitude, {{3525, 100}});
}

ExifInfo Read(const testing::TestExif& tags) {
  const std::vector<unsigned char> block = testing::MakeExifBlock(tags);
  return ReadExifInfo(block.data(), block.size());
}

ExifInfo ReadWith(const std::function<void(ExifData*, ExifByteOrder)>& more) {
  testing::TestExif tags;
  tags.more = more;
  return Read(tags);
}

TEST(ReadExifInfo, ReadsGpsLatitudeLongitudeAndAltitude) {
  const ExifInfo info = ReadWith(AddGoodGps);
  ASSERT_TRUE(info.gps);
  EXPECT_NEAR(info.gps->latitude_deg, 48 + 51 / 60.0 + 29.5 / 3600, 1e-12);
  EXPECT_NEAR(info.gps->longitude_deg, 2 + 17 / 60.0 + 40.2 / 3600, 1e-12);
  EXPECT_EQ(info.gps->altitude_m, 35.25);
  EXPECT_TRUE(info.warnings.empty());
  // Through a JPEG file's APP1 segment too.
  testing::TestExif tags;
  tags.more = AddGoodGps;
  const std::vector<unsigned char> jpeg =
      testing::EncodeJpegWithExif(cv::Mat(8, 8, CV_8UC1, cv::Scalar(7)), tags);
  const ExifInfo from_jpeg = ReadExifInfo(jpeg.data(), jpeg.size());
  ASSERT_TRUE(from_jpeg.gps);
  EXPECT_EQ(from_jpeg.gps->latitude_deg, info.gps->latitude_deg);
}

TEST(ReadExifInfo, SouthWestAndBelowSeaLevelAreNegative) {
  const ExifInfo info = ReadWith([](ExifData* data, ExifByteOrder order) {
    AddAscii(data, EXIF_IFD_GPS, kGpsLatitudeRef, "S");
    AddRationals(data, order, kGpsLatitude, {{33, 1}, {30, 1}, {0, 1}});
    AddAscii(data, EXIF_IFD_GPS, kGpsLongitudeRef, "W");
    AddRationals(data, order, kGpsLongitude, {{7015, 100}, {0, 1}, {0, 1}});
    AddByte(data, kGpsAltitudeRef, 1);
    AddRationals(data, order, kGpsAltitude, {{12, 1}});
  });
  ASSERT_TRUE(info.gps);
  EXPECT_DOUBLE_EQ(info.gps->latitude_deg, -33.5);
  EXPECT_DOUBLE_EQ(info.gps->longitude_deg, -70.15);
  EXPECT_EQ(info.gps->altitude_m, -12);
}

TEST(ReadExifInfo, GpsWithoutAltitudeHasNone) {
  const ExifInfo info = ReadWith([](ExifData* data, ExifByteOrder order) {
    AddAscii(data, EXIF_IFD_GPS, kGpsLatitudeRef, "N");
    AddRationals(data, order, kGpsLatitude, {{10, 1}, {0, 1}, {0, 1}});
    AddAscii(data, EXIF_IFD_GPS, kGpsLongitudeRef, "E");
    AddRationals(data, order, kGpsLongitude, {{20, 1}, {0, 1}, {0, 1}});
  });
  ASSERT_TRUE(info.gps);
  EXPECT_EQ(info.gps->latitude_deg, 10);
  EXPECT_EQ(info.gps->longitude_deg, 20);
  EXPECT_FALSE(info.gps->altitude_m);
  EXPECT_TRUE(info.warnings.empty());
}

// Each malformed variant drops the whole fix with one warning naming the tag.
TEST(ReadExifInfo, MalformedGpsIsDroppedWithAWarning) {
  struct Case {
    std::string expected_warning;
    std::function<void(ExifData*, ExifByteOrder)> add;
  };
  const auto lat_ref = [](ExifData* data) { AddAscii(data, EXIF_IFD_GPS, kGpsLatitudeRef, "N"); };
  const auto good_longitude = [](ExifData* data, ExifByteOrder order) {
    AddAscii(data, EXIF_IFD_GPS, kGpsLongitudeRef, "E");
    AddRationals(data, order, kGpsLongitude, {{2, 1}, {0, 1}, {0, 1}});
  };
  const std::vector<Case> cases = {
      {"GPS ignored: GPSLatitude has 2 components, expected 3",
       [&](ExifData* data, ExifByteOrder order) {
         lat_ref(data);
         AddRationals(data, order, kGpsLatitude, {{48, 1}, {51, 1}});
         good_longitude(data, order);
       }},
      {"GPS ignored: GPSLatitude has format SRational, expected Rational",
       [&](ExifData* data, ExifByteOrder order) {
         lat_ref(data);
         AddRationals(data, order, kGpsLatitude, {{48, 1}, {51, 1}, {0, 1}}, EXIF_FORMAT_SRATIONAL);
         good_longitude(data, order);
       }},
      {"GPS ignored: GPSLatitude has a zero denominator",  // 0/0: NaN
       [&](ExifData* data, ExifByteOrder order) {
         lat_ref(data);
         AddRationals(data, order, kGpsLatitude, {{48, 1}, {0, 0}, {0, 1}});
         good_longitude(data, order);
       }},
      {"GPS ignored: GPSLatitude is out of range (91.000000 degrees)",
       [&](ExifData* data, ExifByteOrder order) {
         lat_ref(data);
         AddRationals(data, order, kGpsLatitude, {{91, 1}, {0, 1}, {0, 1}});
         good_longitude(data, order);
       }},
      {"GPS ignored: GPSLatitude has minutes or seconds of 60 or more",
       [&](ExifData* data, ExifByteOrder order) {
         lat_ref(data);
         AddRationals(data, order, kGpsLatitude, {{45, 1}, {75, 1}, {0, 1}});
         good_longitude(data, order);
       }},
      {"GPS ignored: GPSLongitude is out of range (180.500000 degrees)",
       [&](ExifData* data, ExifByteOrder order) {
         lat_ref(data);
         AddRationals(data, order, kGpsLatitude, {{45, 1}, {0, 1}, {0, 1}});
         AddAscii(data, EXIF_IFD_GPS, kGpsLongitudeRef, "W");
         AddRationals(data, order, kGpsLongitude, {{180, 1}, {30, 1}, {0, 1}});
       }},
      {"GPS ignored: GPSLatitudeRef is 'X', expected 'N' or 'S'",
       [&](ExifData* data, ExifByteOrder order) {
         AddAscii(data, EXIF_IFD_GPS, kGpsLatitudeRef, "X");
         AddRationals(data, order, kGpsLatitude, {{45, 1}, {0, 1}, {0, 1}});
         good_longitude(data, order);
       }},
      {"GPS ignored: GPSLongitude is missing",
       [&](ExifData* data, ExifByteOrder order) {
         lat_ref(data);
         AddRationals(data, order, kGpsLatitude, {{45, 1}, {0, 1}, {0, 1}});
       }},
      {"GPS ignored: GPSAltitude has a zero denominator",
       [&](ExifData* data, ExifByteOrder order) {
         lat_ref(data);
         AddRationals(data, order, kGpsLatitude, {{45, 1}, {0, 1}, {0, 1}});
         good_longitude(data, order);
         AddRationals(data, order, kGpsAltitude, {{5, 0}});
       }},
      {"GPS ignored: GPSAltitudeRef is 7, expected 0 or 1",
       [&](ExifData* data, ExifByteOrder order) {
         lat_ref(data);
         AddRationals(data, order, kGpsLatitude, {{45, 1}, {0, 1}, {0, 1}});
         good_longitude(data, order);
         AddByte(data, kGpsAltitudeRef, 7);
         AddRationals(data, order, kGpsAltitude, {{5, 1}});
       }},
  };
  for (const Case& test_case : cases) {
    const ExifInfo info = ReadWith(test_case.add);
    EXPECT_FALSE(info.gps) << test_case.expected_warning;
    EXPECT_EQ(info.warnings, std::vector<std::string>{test_case.expected_warning});
  }
}

TEST(ReadExifInfo, ReadsCaptureTimeWithSubSeconds) {
  const ExifInfo info = ReadWith([](ExifData* data, ExifByteOrder) {
    AddAscii(data, EXIF_IFD_EXIF, EXIF_TAG_DATE_TIME_ORIGINAL, "2010:01:01 00:00:10");
    AddAscii(data, EXIF_IFD_EXIF, EXIF_TAG_SUB_SEC_TIME_ORIGINAL, "25");
  });
  ASSERT_TRUE(info.capture_time_s);
  EXPECT_DOUBLE_EQ(*info.capture_time_s, 1262304010.25);  // `date -u -d 2010-01-01 +%s` + 10.25
  EXPECT_TRUE(info.warnings.empty());

  const ExifInfo blank = ReadWith([](ExifData* data, ExifByteOrder) {
    AddAscii(data, EXIF_IFD_EXIF, EXIF_TAG_DATE_TIME_ORIGINAL, "    :  :     :  :  ");
  });
  EXPECT_FALSE(blank.capture_time_s);
  EXPECT_TRUE(blank.warnings.empty());

  const ExifInfo bad = ReadWith([](ExifData* data, ExifByteOrder) {
    AddAscii(data, EXIF_IFD_EXIF, EXIF_TAG_DATE_TIME_ORIGINAL, "2010:13:01 00:00:10");
  });
  EXPECT_FALSE(bad.capture_time_s);
  EXPECT_EQ(bad.warnings, std::vector<std::string>{"DateTimeOriginal ignored: '2010:13:01 "
                                                   "00:00:10' is not a date 'YYYY:MM:DD "
                                                   "HH:MM:SS'"});
}

TEST(ParseExifDateTime, CountsDaysAcrossLeapYears) {
  EXPECT_EQ(ParseExifDateTime("1970:01:01 00:00:00", ""), 0.0);
  EXPECT_EQ(ParseExifDateTime("2000:03:01 12:30:00", ""), 951913800.0);
  EXPECT_EQ(ParseExifDateTime("2024:02:29 23:59:59", "5"), 1709251199.5);
  EXPECT_FALSE(ParseExifDateTime("2024-02-29 23:59:59", ""));
  EXPECT_FALSE(ParseExifDateTime("2024:02:29", ""));
}

TEST(ReadExifInfo, GarbageNeverCrashes) {
  // Random bytes after an EXIF header: libexif rejects or half-reads them; no GPS comes
  // out of noise, and nothing throws.
  uint32_t state = 12345;
  for (int trial = 0; trial < 200; ++trial) {
    testing::TestExif tags;
    tags.more = AddGoodGps;
    std::vector<unsigned char> mutated = testing::MakeExifBlock(tags);
    for (int k = 0; k < 8; ++k) {
      state = state * 1664525u + 1013904223u;
      mutated[6 + state % (mutated.size() - 6)] = static_cast<unsigned char>(state >> 24);
    }
    const ExifInfo info = ReadExifInfo(mutated.data(), mutated.size());
    if (info.gps) {
      EXPECT_LE(std::abs(info.gps->latitude_deg), 90);
      EXPECT_LE(std::abs(info.gps->longitude_deg), 180);
    }
  }
}

}  // namespace
}  // namespace tessera
