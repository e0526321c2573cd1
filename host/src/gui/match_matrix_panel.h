#pragma once

// The match matrix window of a workspace: images by images, each cell coloured by the
// pair's verified inliers (dark blue: none, to yellow: the most); a click on a cell shows
// the pair's two photographs side by side with their inlier matches drawn between them.

#include <imgui.h>

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "gui/match_matrix.h"
#include "gui/pair_view.h"
#include "gui/widget_rects.h"

namespace tessera::gui {

// Every how many rows or columns the matrix labels one (1, 2, 5, 10, 20, ...): the
// smallest step whose cells span `label_extent` pixels (a label's height for the rows,
// its width and a gap for the columns).
size_t MatrixLabelStep(float cell, float label_extent);

// Whether `a` and `b` name the same folder (the same file when both exist, else the same
// path once normal: "out/" is "out"); two empty paths are the same.
bool SameFolder(const std::filesystem::path& a, const std::filesystem::path& b);

class MatchMatrixPanel {
 public:
  // Where the column numbers were drawn in the last frame (they never overlap).
  const std::vector<WidgetRect>& column_labels() const { return column_labels_; }
  // Opens the match matrix of the workspace `path` (its database.db); false with the
  // message in Error() (also logged) when it cannot.
  bool Open(const std::filesystem::path& path);
  // Closes the window and forgets the matrix.
  void Close();
  // Called each frame with the workspace of the model shown (empty: none) and whether a
  // run is writing it: when that workspace changes, an open matrix of another one is
  // replaced by its (or closed: no workspace, or one being written, reopened once the
  // run ends). The matrix and the 3D view never show two workspaces.
  void FollowModel(const std::filesystem::path& workspace, bool being_written);
  // A run starts into `workspace`: an open matrix of it is closed (its matches are
  // rewritten) and reopened, read anew, when the run ends (RunEnded).
  void RunStarted(const std::filesystem::path& workspace);
  void RunEnded();
  // The workspace of the matrix open; empty when none.
  const std::filesystem::path& workspace() const { return workspace_; }
  // The matrix open; nullptr when none.
  const MatchMatrix* matrix() const { return show_ && matrix_ ? &*matrix_ : nullptr; }

  // The "Match matrix" button of the set-up window (opens the matrix of `workspace`, the
  // model's, else the output folder), recorded as "match matrix", and the message of the
  // last failure.
  void DrawOpenButton(const std::filesystem::path& workspace, WidgetRects* widgets);
  // The window, while open, at the top left of `view_rect`; the photographs of a pair are
  // read from `image_dir`. Records "match cells".
  void Draw(const WidgetRect& view_rect, const std::filesystem::path& image_dir,
            WidgetRects* widgets);

  const std::string& Error() const { return error_; }
  // The pair (row, column) clicked and its inlier matches; (-1, -1) when none.
  std::pair<int, int> SelectedPair() const { return {pair_row_, pair_column_}; }
  const PairInliers& SelectedPairInliers() const { return pair_view_.pair(); }
  PairView& pair_view() { return pair_view_; }
  const PairView& pair_view() const { return pair_view_; }

 private:
  std::vector<WidgetRect> column_labels_;
  // The cells, `cell` pixels square, as one item recorded as "match cells"; hovering
  // shows a pair's count, a click selects it.
  // The cells at `cell` pixels, less where the names and the cells would not fit in
  // `room` (the width and height they may take).
  void DrawCells(float cell, const ImVec2& room, const std::filesystem::path& image_dir,
                 WidgetRects* widgets);
  // Reads the inlier matches of (row, column) and loads its photographs.
  void SelectPair(int row, int column, const std::filesystem::path& image_dir);
  // The colour scale under the cells, recorded as "matrix legend".
  void DrawLegend(WidgetRects* widgets);

  bool show_ = false;
  std::optional<MatchMatrix> matrix_;
  std::filesystem::path workspace_;        // of matrix_
  std::filesystem::path model_workspace_;  // FollowModel's last
  std::filesystem::path reopen_after_run_;
  std::string error_;
  int pair_row_ = -1, pair_column_ = -1;
  PairView pair_view_;
};

}  // namespace tessera::gui
