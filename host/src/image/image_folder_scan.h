#pragma once

// Finding the input images and reading their sizes and EXIF without decoding them.
// Decoding them the way detection and colouring see them is tessera/io/image_io.h
// (included here: the scan accepts exactly what those functions decode).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "image/camera_assignment.h"  // the pipeline makes cameras right after the scan
#include "image/image_entry.h"
#include "image/image_limits.h"
#include "tessera/io/image_io.h"

namespace tessera {

struct ImageScan {
  std::vector<ImageEntry> images;            // usable images, natural-sorted by name
  std::vector<std::string> warnings;         // one sentence per skipped entry, naming it and why;
                                             // sorted by name
  std::vector<std::string> skipped_folders;  // one sentence per folder left out, and why
};

struct ImageScanOptions {
  // Folders never scanned (the run's own output folder): output never feeds input.
  std::vector<std::filesystem::path> excluded_folders;
  int64_t max_image_pixels = kDefaultMaxImagePixels;  // refused before decoding
  // The mask folder (camera.mask_path), never scanned for images; empty: none.
  std::filesystem::path mask_folder;
};

// A folder holding a Tessera workspace (a database.db or a .tessera.lock file).
bool IsTesseraWorkspace(const std::filesystem::path& dir);

// A folder holding Tessera's outputs (an outputs ledger, .tessera_outputs.json): an
// export's folder, which holds no lock (tessera export --output IMG/out).
bool HoldsTesseraOutputs(const std::filesystem::path& dir);

// Scans `dir` and its sub-folders (hidden files and folders excepted, counted in one
// line of skipped_folders) for files ending
// in .jpg, .jpeg, .png, .tif or .tiff in any case; names are relative to `dir`. The
// format is told by the file's signature, not its extension. Sizes come from the
// headers (JPEG SOF, PNG IHDR); JPEG and PNG files are also checked to be complete
// (JPEG: an end-of-image marker after the image data; PNG: an IEND chunk), so that
// a truncated file is skipped here rather than decoded to grey later. TIFF files
// are decoded. Throws InputError naming the folder if it does not exist. Files that
// are not usable images are skipped with a warning each, and so are images of more
// than options.max_image_pixels pixels and names with a line break (which a COLMAP
// text model cannot hold). So is every entry named like an image that is no readable
// file: a folder, a dangling symbolic link, a FIFO, device or socket (or a link to
// one), a file that cannot be opened (the system's reason quoted); and every folder
// that cannot be listed or is a symbolic link (not followed). FIFOs and devices are
// never opened, so none can block the scan. The excluded folders, every Tessera
// workspace and every folder holding Tessera's outputs (HoldsTesseraOutputs: an export
// put inside the image folder) below `dir` are left out, each with a line in
// skipped_folders: output never feeds input. Every
// image gets its size and content hash.
ImageScan ScanImageFolder(const std::filesystem::path& dir, const ImageScanOptions& options = {});

}  // namespace tessera
