#include "video/video_frames.h"

#include <spdlog/spdlog.h>
#include <xxhash.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <optional>
#include <set>

#include "io/names.h"
#include "tessera/errors.h"
#include "tessera/io/file_io.h"
#include "tessera/option_list.h"
#include "tessera/options.h"
#include "util/timer.h"
#include "util/workspace_layout.h"
#include "video/video_decoder.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

// The analysis image: grey, longer side `size` (never enlarged).
cv::Mat AnalysisImage(const cv::Mat& frame, int size) {
  cv::Mat gray;
  if (frame.channels() == 3) {
    cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
  } else if (frame.channels() == 4) {
    cv::cvtColor(frame, gray, cv::COLOR_BGRA2GRAY);
  } else {
    gray = frame;
  }
  const int longer = std::max(gray.cols, gray.rows);
  if (longer <= size) return gray.clone();
  const double scale = static_cast<double>(size) / longer;
  cv::Mat small;
  cv::resize(gray, small, cv::Size(), scale, scale, cv::INTER_AREA);
  return small;
}

// Median length of the optical flow, sampled on a 4-pixel grid.
double MedianFlow(const cv::Mat& flow) {
  std::vector<float> lengths;
  lengths.reserve(static_cast<size_t>(flow.rows / 4 + 1) * (flow.cols / 4 + 1));
  for (int y = 0; y < flow.rows; y += 4) {
    const cv::Vec2f* row = flow.ptr<cv::Vec2f>(y);
    for (int x = 0; x < flow.cols; x += 4) lengths.push_back(std::hypot(row[x][0], row[x][1]));
  }
  if (lengths.empty()) return 0;
  std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  return lengths[lengths.size() / 2];
}

double FrameTime(int index, double fps, const VideoDecoder& decoder) {
  if (fps > 0) return index / fps;
  return decoder.PositionSeconds();
}

// XXH3-128 of the file's bytes, 32 hex digits as the images' content hashes, read in
// blocks (a video need not fit in memory); "" when it cannot be read.
std::string FileContentHash(const fs::path& file) {
  std::ifstream stream(file, std::ios::binary);
  if (!stream) return "";
  std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)> state(XXH3_createState(),
                                                                 &XXH3_freeState);
  XXH3_128bits_reset(state.get());
  std::vector<char> block(size_t{1} << 20);
  while (stream) {
    stream.read(block.data(), static_cast<std::streamsize>(block.size()));
    XXH3_128bits_update(state.get(), block.data(), static_cast<size_t>(stream.gcount()));
  }
  if (stream.bad()) return "";
  const XXH128_hash_t hash = XXH3_128bits_digest(state.get());
  char text[33];
  std::snprintf(text, sizeof(text), "%016llx%016llx", static_cast<unsigned long long>(hash.high64),
                static_cast<unsigned long long>(hash.low64));
  return text;
}

nlohmann::json Record(const VideoFrames& result, const VideoFrameOptions& options) {
  std::error_code error;
  nlohmann::json frames = nlohmann::json::array();
  std::map<size_t, std::string> image_of;
  for (size_t k = 0; k < result.selection.selected.size(); ++k) {
    image_of[result.selection.selected[k]] = result.images[k];
  }
  for (size_t i = 0; i < result.frames.size(); ++i) {
    const FrameScore& frame = result.frames[i];
    nlohmann::json entry = {{"index", frame.index},
                            {"time_s", frame.time_s},
                            {"sharpness", frame.sharpness},
                            {"motion_px", frame.motion},
                            {"segment", result.selection.segment[i]},
                            {"selected", image_of.count(i) > 0}};
    if (image_of.count(i)) entry["image"] = image_of[i];
    frames.push_back(entry);
  }
  const fs::path absolute = fs::absolute(result.video).lexically_normal();
  return {{"file", absolute.string()},
          {"size", static_cast<uint64_t>(fs::file_size(result.video, error))},
          {"content_hash", result.content_hash},
          {"options", options.ToJson()},
          {"folder", result.folder},
          {"fps", result.fps},
          {"width", result.width},
          {"height", result.height},
          {"num_frames", result.frames.size()},
          {"num_selected", result.selection.selected.size()},
          {"num_segments", result.selection.num_segments},
          {"total_motion_px", result.selection.total_motion},
          {"frames", frames}};
}

// Throws InputError naming frames.json when `image`, a kept frame it records, is not one
// Tessera writes: a relative, normal path (CheckPathBelow: nothing through a link) right
// in its video's folder. The frame is read as an image of the run.
void CheckRecordedFrame(const std::string& image, const std::string& folder,
                        const fs::path& frames_dir) {
  const std::string where = (frames_dir.parent_path() / workspace_layout::kFramesFile).string();
  CheckPathBelow(frames_dir, image, where);
  const std::string prefix = folder + "/";
  if (image.compare(0, prefix.size(), prefix) != 0 ||
      image.find('/', prefix.size()) != std::string::npos) {
    throw InputError(where + ": the frame '" + image + "' does not lie in " +
                     (frames_dir / folder).string() +
                     ", where Tessera writes its video's frames; delete frames.json to decode "
                     "the videos again");
  }
}

// Throws InputError when `folder`, one Tessera writes frames in and removes old ones
// from, is a symbolic link: nothing is written or removed through one.
void RefuseLink(const fs::path& folder) {
  std::error_code error;
  if (fs::symlink_status(folder, error).type() == fs::file_type::symlink) {
    throw InputError(folder.string() +
                     " is a symbolic link; Tessera writes video frames there and removes old "
                     "ones, never through a link: move it away");
  }
}

// The earlier run's selection of this video, when nothing it depends on changed: the
// same file with the same content (its hash: a file replaced by another of the same size
// and modification time is decoded again) and options.
std::optional<VideoFrames> Reuse(const nlohmann::json& recorded, const VideoFrames& probe,
                                 const VideoFrameOptions& options, const fs::path& frames_dir) {
  if (probe.content_hash.empty()) return std::nullopt;  // unreadable: decoding says why
  const nlohmann::json now = Record(probe, options);
  for (const nlohmann::json& video : recorded.value("videos", nlohmann::json::array())) {
    if (!video.is_object() || video.value("file", "") != now["file"] ||
        video.value("size", nlohmann::json()) != now["size"] ||
        video.value("content_hash", "") != probe.content_hash ||
        video.value("options", nlohmann::json()) != now["options"] ||
        video.value("folder", "") != probe.folder) {
      continue;
    }
    try {
      VideoFrames result = probe;
      result.reused = true;
      result.fps = video.at("fps").get<double>();
      result.width = video.at("width").get<int>();
      result.height = video.at("height").get<int>();
      result.selection.num_segments = video.at("num_segments").get<int>();
      result.selection.total_motion = video.at("total_motion_px").get<double>();
      for (const nlohmann::json& frame : video.at("frames")) {
        result.frames.push_back({frame.at("index").get<int>(), frame.at("time_s").get<double>(),
                                 frame.at("sharpness").get<double>(),
                                 frame.at("motion_px").get<double>()});
        result.selection.segment.push_back(frame.at("segment").get<int>());
        if (frame.at("selected").get<bool>()) {
          result.selection.selected.push_back(result.frames.size() - 1);
          result.images.push_back(frame.at("image").get<std::string>());
          CheckRecordedFrame(result.images.back(), probe.folder, frames_dir);
          std::error_code error;
          if (!fs::is_regular_file(frames_dir / result.images.back(), error)) return std::nullopt;
        }
      }
      return result;
    } catch (const nlohmann::json::exception&) {
      return std::nullopt;  // a damaged record: decode again
    }
  }
  return std::nullopt;
}

}  // namespace

nlohmann::json VideoFrameOptions::ToJson() const {
  return {
      {"min_frames", selection.min_frames},       {"max_frames", selection.max_frames},
      {"target_frames", selection.target_frames}, {"keyframe_motion", selection.keyframe_motion},
      {"analysis_size", analysis_size},           {"jpeg_quality", jpeg_quality}};
}

VideoFrameOptions VideoFrameOptions::FromJson(const nlohmann::json& json) {
  OptionReader reader(json, "video");
  VideoFrameOptions options;
  const KeyframeSelectionOptions& s = options.selection;
  VisitKeyframeSelectionOptions(options.selection, option_list::Reader(&reader));
  VisitVideoFrameOptions(options, option_list::Reader(&reader));
  reader.Finish();
  if (s.min_frames > s.max_frames) {
    throw OptionError("video.min_frames",
                      "must not exceed max_frames (" + std::to_string(s.max_frames) + ")");
  }
  return options;
}

void VideoFrameOptions::Check() const {
  selection.Check();
  VisitVideoFrameOptions(*this, option_list::Checker("VideoFrameOptions"));
}

std::string VideoFrameName(int index, double time_s) {
  char name[64];
  std::snprintf(name, sizeof(name), "frame_%06d_%.3fs.jpg", index, time_s);
  return name;
}

VideoFrames ExtractVideoFrames(const fs::path& video, const std::string& folder,
                               const fs::path& frames_dir, const VideoFrameOptions& options) {
  options.Check();
  VideoFrames result;
  result.video = video;
  result.folder = folder;
  std::unique_ptr<VideoDecoder> decoder = OpenVideoDecoder(video);
  result.fps = decoder->FramesPerSecond();
  if (!(result.fps > 0 && result.fps < 10000)) result.fps = 0;

  Timer decode_timer;
  double decode_seconds = 0, select_seconds = 0;
  cv::Ptr<cv::DISOpticalFlow> flow_estimator =
      cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_FAST);
  cv::Mat frame, previous, flow;
  double flow_scale = 1;
  for (int index = 0;; ++index) {
    const Timer read_timer;
    const bool read = decoder->Read(&frame);
    decode_seconds += read_timer.ElapsedSeconds();
    if (!read || frame.empty()) break;
    const Timer score_timer;
    if (index == 0) {
      result.width = frame.cols;
      result.height = frame.rows;
    }
    const cv::Mat gray = AnalysisImage(frame, options.analysis_size);
    flow_scale =
        static_cast<double>(std::max(frame.cols, frame.rows)) / std::max(gray.cols, gray.rows);
    FrameScore score;
    score.index = index;
    score.time_s = FrameTime(index, result.fps, *decoder);
    score.sharpness = LocalLaplacianSharpness(gray);
    if (!previous.empty() && previous.size() == gray.size()) {
      flow_estimator->calc(previous, gray, flow);
      score.motion = MedianFlow(flow) * flow_scale;
    }
    previous = gray;
    result.frames.push_back(score);
    select_seconds += score_timer.ElapsedSeconds();
  }
  if (result.frames.empty()) {
    throw InputError(video.string() + ": the video has no decodable frame");
  }
  const Timer select_timer;
  result.selection =
      SelectKeyframes(result.frames, std::max(result.width, result.height), options.selection);
  select_seconds += select_timer.ElapsedSeconds();
  if (result.selection.too_few_frames) {
    spdlog::warn("{}: {} usable frames, fewer than min_frames ({}); every one is kept",
                 video.string(), result.frames.size(), options.selection.min_frames);
  }

  // Second pass: write the selected frames.
  const fs::path dir = frames_dir / folder;
  RefuseLink(dir);
  CreateFolder(dir);
  std::set<std::string> names;
  for (const size_t i : result.selection.selected) {
    result.images.push_back(folder + "/" +
                            VideoFrameName(result.frames[i].index, result.frames[i].time_s));
    names.insert(VideoFrameName(result.frames[i].index, result.frames[i].time_s));
  }
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(dir, error)) {
    if (entry.path().extension() == ".jpg" && !names.count(entry.path().filename().string())) {
      fs::remove(entry.path(), error);  // an earlier selection's
    }
  }
  decoder = OpenVideoDecoder(video);
  size_t next = 0;
  for (int index = 0; next < result.selection.selected.size(); ++index) {
    const Timer read_timer;
    bool read = decoder->Grab();
    const bool wanted = read && index == result.frames[result.selection.selected[next]].index;
    if (wanted) read = decoder->Retrieve(&frame);
    decode_seconds += read_timer.ElapsedSeconds();
    if (!read) break;
    if (!wanted) continue;
    std::vector<uchar> bytes;
    cv::imencode(".jpg", frame, bytes, {cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality});
    WriteFileAtomically(frames_dir / result.images[next], std::string(bytes.begin(), bytes.end()));
    ++next;
  }
  if (next < result.selection.selected.size()) {
    throw InputError(video.string() + ": frame " +
                     std::to_string(result.frames[result.selection.selected[next]].index) +
                     " could not be decoded again (the file changed while it was read?)");
  }
  result.decode_seconds = decode_seconds;
  result.select_seconds = select_seconds;
  (void)decode_timer;
  return result;
}

namespace {

// The folder below video_frames/ of each video: its name's stem, made unique. Its frames
// are images named <folder>/frame_...jpg, so each name is checked as an image name: a
// control character in a video's name would be in every one of them.
std::vector<std::string> VideoFolders(const std::vector<fs::path>& videos) {
  std::vector<std::string> folders;
  std::set<std::string> taken;
  for (const fs::path& video : videos) {
    std::string folder = video.stem().string();
    if (folder.empty() || folder[0] == '.') folder = "video" + folder;
    for (int k = 2; taken.count(folder); ++k)
      folder = video.stem().string() + "_" + std::to_string(k);
    taken.insert(folder);
    CheckImageName(folder + "/" + VideoFrameName(0, 0),
                   "video '" + EscapeControlCharacters(video.string()) + "'");
    folders.push_back(folder);
  }
  return folders;
}

}  // namespace

fs::path IngestVideos(const std::vector<fs::path>& videos, const fs::path& output_dir,
                      const VideoFrameOptions& options, std::vector<VideoFrames>* results) {
  const fs::path frames_dir = output_dir / workspace_layout::kVideoFramesFolder;
  const fs::path record_file = output_dir / workspace_layout::kFramesFile;
  nlohmann::json recorded = nlohmann::json::object();
  std::error_code error;
  if (fs::exists(record_file, error)) {
    try {
      recorded = nlohmann::json::parse(ReadFileContents(record_file));
    } catch (const std::exception&) {
      recorded = nlohmann::json::object();  // damaged: every video is decoded again
    }
  }
  const std::vector<std::string> folders = VideoFolders(videos);  // before anything is written
  RefuseLink(frames_dir);
  for (const std::string& folder : folders) RefuseLink(frames_dir / folder);
  CreateFolder(frames_dir);
  nlohmann::json record = {{"videos", nlohmann::json::array()}};
  for (size_t index = 0; index < videos.size(); ++index) {
    const fs::path& video = videos[index];
    const std::string& folder = folders[index];
    VideoFrames probe;
    probe.video = video;
    probe.folder = folder;
    std::optional<VideoFrames> reused;
    if (fs::is_regular_file(video, error)) {
      probe.content_hash = FileContentHash(video);
      reused = Reuse(recorded, probe, options, frames_dir);
    }
    VideoFrames result;
    if (reused) {
      result = *reused;
      spdlog::info("video: {}: the {} frames selected by an earlier run are unchanged; reused",
                   video.string(), result.images.size());
    } else {
      result = ExtractVideoFrames(video, folder, frames_dir, options);
      result.content_hash = probe.content_hash;  // of the bytes before decoding
      spdlog::info(
          "video: {}: {} frames decoded ({}x{}, {:.2f} fps), accumulated motion {:.0f} px, {} "
          "kept in {} segments, into {}; {:.1f} frames/s decoded, selection {:.2f} ms per "
          "frame",
          video.string(), result.frames.size(), result.width, result.height, result.fps,
          result.selection.total_motion, result.images.size(), result.selection.num_segments,
          (frames_dir / folder).string(),
          result.frames.size() / std::max(1e-9, result.decode_seconds),
          1000 * result.select_seconds / result.frames.size());
    }
    record["videos"].push_back(Record(result, options));
    if (results) results->push_back(std::move(result));
  }
  // Folders of videos no longer given: their frames would be scanned as images.
  for (const auto& entry : fs::directory_iterator(frames_dir, error)) {
    if (entry.is_directory() && std::find(folders.begin(), folders.end(),
                                          entry.path().filename().string()) == folders.end()) {
      spdlog::info("video: removing {}: its video is not among this run's", entry.path().string());
      fs::remove_all(entry.path(), error);
    }
  }
  WriteFileAtomically(record_file, record.dump(2) + "\n");
  return frames_dir;
}

}  // namespace tessera
