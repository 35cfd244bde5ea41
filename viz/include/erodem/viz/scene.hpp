// erodem viewer — the VTK scene: the terrain surface, the water surface, the scalar bar and
// the text overlays, rendered in a window or off screen, and picking.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "erodem/viz/colormap.hpp"
#include "erodem/viz/lod.hpp"
#include "erodem/viz/view_data.hpp"

class vtkRenderWindow;
class vtkRenderer;

namespace erodem::viz {

/// How the scene starts.
struct SceneOptions {
  std::string field = "bed";          ///< field the terrain is coloured by
  std::size_t time_index = 0;         ///< snapshot shown
  double exaggeration = 0.0;          ///< vertical exaggeration (1); 0 = auto_exaggeration()
  double water_threshold = 0.05;      ///< water is drawn where the depth exceeds this (m)
  std::size_t max_cells = 4'000'000;  ///< above this many cells, draw a decimated copy
  /// Interactive mode: while the camera moves, draw a copy of at most this many cells (and
  /// no water), so that large grids follow the mouse with software rendering too.
  std::size_t interaction_cells = 100'000;
  int width = 1200, height = 800;  ///< window or image size (pixels)
  bool offscreen = false;          ///< render off screen (screenshots, --pick)
  bool top_view = false;           ///< look straight down (north up) instead of oblique
  /// The colour map of `field` instead of its own (--cmap); other fields keep theirs.
  std::optional<ColorMap> cmap;
  /// The colour range of `field` (--clim LO,HI) instead of the computed one.
  std::optional<std::array<double, 2>> clim;
  /// Recompute the colour range at every snapshot (--rescale) instead of holding one range
  /// over all snapshots (ViewData::held_color_range).
  bool rescale = false;
  bool water = true;  ///< draw the water surface (--no-water: false)
};

/// The scale bar and north arrow as last drawn: `metres` of ground (at the focal point,
/// along the screen's horizontal) are `pixels` long on screen; north points
/// `north_degrees` clockwise from straight up.
struct ScaleBar {
  double metres = 0.0, pixels = 0.0, north_degrees = 0.0;
};

/// A vertical exaggeration that makes the relief about 15 % of the horizontal extent,
/// within [1, 5] (1 for a flat grid).
double auto_exaggeration(const Grid& grid, const std::vector<float>& bed);

/// A picked cell: where the pick hit the terrain and the full-resolution values there.
struct PickResult {
  std::array<double, 3> world{};  ///< pick position (world m, z exaggerated)
  CellValues cell;                ///< the full-resolution cell under it and its values
};

/// The scene. The terrain mesh has a vertex per (possibly decimated) cell centre at
/// (world x, world y, bed), two triangles per quad of valid vertices, and normals from
/// central differences; the exaggeration is the actors' z scale, so changing it costs no
/// rebuild. The water surface is a second, translucent mesh at bed + depth over the
/// quads with a vertex deeper than the threshold (not pickable).
class Scene {
 public:
  /// Builds the scene of `data` (which must outlive it). Unknown field -> Error(data).
  Scene(ViewData& data, const SceneOptions& options);
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  ViewData& data() { return data_; }
  const Lod& lod() const { return lod_; }
  const std::string& field() const { return field_; }
  std::size_t time_index() const { return time_index_; }
  double exaggeration() const { return exaggeration_; }
  bool water_visible() const;
  /// The colour map and range the terrain is drawn with now.
  ColorMap color_map() const;
  std::array<double, 2> color_limits() const;
  /// Whether the current snapshot has values below / above the colour range (the bar then
  /// shows a triangle at that end).
  std::array<bool, 2> clipped() const;
  /// The scale bar and north arrow as computed for the last render.
  ScaleBar scale_bar() const;

  /// Colours the terrain by `name` (Error(data) when unknown).
  void set_field(const std::string& name);
  /// Shows snapshot `index` (clamped to the stored ones).
  void set_time_index(std::size_t index);
  /// Sets the vertical exaggeration (clamped to [0.01, 1000]).
  void set_exaggeration(double exaggeration);
  void set_water_visible(bool visible);
  /// Whether a coarser copy is drawn while the camera moves (interactive mode only).
  bool has_interaction_lod() const;
  /// Switches to the coarser copy (true: the camera is moving) and back.
  void set_interacting(bool interacting);
  /// Turns the camera about the vertical through the focal point (degrees).
  void orbit(double degrees);
  /// Places the camera: oblique from the south, or straight down.
  void reset_camera(bool top_view);

  /// Renders once (off screen or in the window).
  void render();
  /// Lays out the scale bar and north arrow for the current camera and window size; called
  /// before each render (an observer of the renderer's StartEvent).
  void update_overlays();
  /// Display position (pixels, origin bottom-left) of CRS point (x, y) on the terrain
  /// surface; nullopt when the point is outside the grid or on a nodata cell.
  std::optional<std::array<double, 2>> display_of(double x, double y);
  /// Picks the terrain at display position (px, py) with a vtkCellPicker and maps the hit
  /// back to the full-resolution cell; nullopt when nothing is hit. Marks the cell (a
  /// magenta pin), shows its values in the panel at the bottom left and, for a file with
  /// several snapshots, its water depth, speed and bed over time in a chart (vtkChartXY)
  /// above the panel.
  std::optional<PickResult> pick(double px, double py);
  /// Writes the current image as a PNG (through a temporary file in the same folder,
  /// renamed into place); Error(cant_create) or Error(io) naming `path` on failure.
  void write_png(const std::string& path);

  vtkRenderWindow* window();
  vtkRenderer* renderer();

 private:
  struct Impl;
  ViewData& data_;
  std::unique_ptr<Impl> impl_;
  Lod lod_;
  std::string field_;
  std::size_t time_index_ = 0;
  double exaggeration_ = 1.0;
  double water_threshold_ = 0.05;
  SceneOptions options_;
  void rebuild_geometry();
  void place_marker();
  void show_series(int col, int row);
  void update_colors();
  void update_status();
};

/// One line of text: "field = value units" for every value of a pick, with the cell and
/// coordinates first ("cell (col 3, row 5)  x = ..., y = ...  t = ... s").
std::string describe_pick(const ViewData& data, const CellValues& cell);
/// The pick as one JSON object on one line (cell, CRS coordinates, lon/lat for geographic
/// grids, time and every value; NaN as null).
std::string pick_json(const ViewData& data, const CellValues& cell);

/// Runs the interactive window until it is closed: trackball camera, time slider, keys.
/// Keys: n / b next / previous field, 1..9 field by number, space play / pause, Right /
/// Left (or . / ,) next / previous time, + / - exaggeration x1.25 / /1.25, w water on / off,
/// t top / oblique view, p or a click pick the cell under the cursor, r reset the camera,
/// q quit.
///
/// `keys` are replayed first, as if typed in the window: single characters, or "space",
/// "plus", "minus", "Right", "Left". With a `screenshot` path the window's image is then
/// written (write_png) and the function returns without waiting for the user: a scripted,
/// testable run of the interactive window.
void run_interactive(Scene& scene, const std::vector<std::string>& keys = {},
                     const std::string& screenshot = "");

}  // namespace erodem::viz
