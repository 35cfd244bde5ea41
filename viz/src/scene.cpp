// erodem viewer — the VTK scene (scene.hpp).
#include "erodem/viz/scene.hpp"

#include <fmt/format.h>
#include <unistd.h>
#include <vtkActor.h>
#include <vtkActor2D.h>
#include <vtkAxis.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellPicker.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkCommand.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkLight.h>
#include <vtkLineSource.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPNGWriter.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataMapper2D.h>
#include <vtkProperty.h>
#include <vtkProperty2D.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkScalarBarActorInternal.h>
#include <vtkSphereSource.h>
#include <vtkStaticCellLocator.h>
#include <vtkTable.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTypeInt32Array.h>
#include <vtkUnsignedCharArray.h>
#include <vtkVariant.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "erodem/error.hpp"
#include "erodem/viz/frame.hpp"

namespace erodem::viz {

namespace {

/// Index of vertex (i, j) of an nx-wide vertex grid.
inline std::size_t vid(int i, int j, int nx) {
  return static_cast<std::size_t>(j) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(i);
}

/// Two triangles per quad of vertices (i, j)..(i+1, j+1) for which `keep(a, b, c, d)` holds.
template <class Keep>
vtkNew<vtkCellArray> quad_triangles(int nx, int ny, Keep keep) {
  vtkNew<vtkTypeInt32Array> conn;
  conn->Allocate(static_cast<vtkIdType>(nx) * ny * 6);
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const auto a = vid(i, j, nx), b = vid(i + 1, j, nx), c = vid(i + 1, j + 1, nx),
                 d = vid(i, j + 1, nx);
      if (!keep(a, b, c, d)) continue;
      for (auto v : {a, d, b, b, d, c}) conn->InsertNextValue(static_cast<std::int32_t>(v));
    }
  vtkNew<vtkCellArray> cells;
  cells->SetData(3, conn);
  return cells;
}

std::string format_value(double v) {
  if (!std::isfinite(v)) return "nodata";
  return fmt::format("{:.6g}", v);
}

std::string json_number(double v) {
  return std::isfinite(v) ? fmt::format("{:.9g}", v) : "null";
}

/// A scalar bar whose above / below range swatches are triangles pointing away from the
/// bar (the colour map's end colours): the mark that values beyond the range are clipped.
class ClipBarActor : public vtkScalarBarActor {
 public:
  static ClipBarActor* New();
  using Superclass = vtkScalarBarActor;

 protected:
  void ConfigureAboveBelowRangeSwatch(bool above) override {
    vtkScalarBarActor::ConfigureAboveBelowRangeSwatch(above);
    if (!(above ? this->DrawAboveRangeSwatch : this->DrawBelowRangeSwatch)) return;
    vtkPolyData* swatch = above ? this->P->AboveRangeSwatch : this->P->BelowRangeSwatch;
    vtkPoints* box = swatch->GetPoints();
    if (!box || box->GetNumberOfPoints() != 4) return;
    // The box is p0, p0 + a, p0 + a + b, p0 + b with a along x and b along y (a vertical
    // bar): the above triangle stands on the bar's top edge, the below one hangs from its
    // bottom edge.
    double p[4][3];
    for (int k = 0; k < 4; ++k) box->GetPoint(k, p[k]);
    vtkNew<vtkPoints> pts;
    const auto mid = [](const double* u, const double* v) {
      return std::array<double, 3>{0.5 * (u[0] + v[0]), 0.5 * (u[1] + v[1]), 0.0};
    };
    if (above) {
      pts->InsertNextPoint(p[0]);
      pts->InsertNextPoint(p[1]);
      pts->InsertNextPoint(mid(p[2], p[3]).data());
    } else {
      pts->InsertNextPoint(p[3]);
      pts->InsertNextPoint(p[2]);
      pts->InsertNextPoint(mid(p[0], p[1]).data());
    }
    vtkNew<vtkCellArray> tri;
    const vtkIdType ids[3] = {0, 1, 2};
    tri->InsertNextCell(3, ids);
    swatch->SetPoints(pts);
    swatch->SetPolys(tri);
  }
};
vtkStandardNewMacro(ClipBarActor);

/// The water's colour: a pure, light blue that neither the terrain map nor the diverging
/// map (purple / orange) uses.
constexpr double kWaterRgb[3] = {0.05, 0.45, 1.0};
/// Water opacity: kWaterAlphaMin at the draw threshold, rising linearly with the depth to
/// kWaterAlphaMax at kWaterOpaqueDepth (m) and deeper.
constexpr double kWaterAlphaMin = 0.35, kWaterAlphaMax = 0.9, kWaterOpaqueDepth = 1.0;
/// The pick marker's colour (magenta: in none of the maps).
constexpr double kMarkerRgb[3] = {1.0, 0.0, 1.0};

/// 1, 2 or 5 times a power of ten, the largest not above x (> 0).
double nice_length(double x) {
  const double p = std::pow(10.0, std::floor(std::log10(x)));
  for (double m : {5.0, 2.0, 1.0})
    if (m * p <= x) return m * p;
  return p;
}

}  // namespace

double auto_exaggeration(const Grid& grid, const std::vector<float>& bed) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (float z : bed)
    if (std::isfinite(z)) {
      lo = std::min(lo, static_cast<double>(z));
      hi = std::max(hi, static_cast<double>(z));
    }
  const double extent = std::max(grid.nx * grid.dx[grid.ny / 2], grid.ny * grid.dy[grid.ny / 2]);
  if (!(hi > lo)) return 1.0;
  return std::clamp(0.15 * extent / (hi - lo), 1.0, 5.0);
}

struct Scene::Impl {
  WorldFrame frame;
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkRenderWindow> window;
  vtkNew<vtkPolyData> terrain;
  vtkNew<vtkPolyDataMapper> terrain_mapper;
  vtkNew<vtkActor> terrain_actor;
  vtkNew<vtkPolyData> water;
  // The coarser copy drawn while the camera moves (interactive mode, large grids).
  Lod interaction_lod;
  vtkNew<vtkPolyData> interaction_terrain;
  vtkNew<vtkPolyDataMapper> interaction_mapper;
  vtkNew<vtkActor> interaction_actor;
  bool interacting = false;
  vtkNew<vtkPolyDataMapper> water_mapper;
  vtkNew<vtkActor> water_actor;
  vtkNew<vtkLookupTable> lut;
  vtkNew<ClipBarActor> bar;
  vtkNew<vtkTextActor> status;
  vtkNew<vtkTextActor> pick_text;
  ColorMap map = ColorMap::terrain;
  std::array<double, 2> limits{0.0, 1.0};
  std::array<bool, 2> clipped{false, false};
  // Scale bar and north arrow: 2-D shapes in display pixels, recomputed before each render.
  vtkNew<vtkPolyData> overlay;
  vtkNew<vtkPolyDataMapper2D> overlay_mapper;
  vtkNew<vtkActor2D> overlay_actor;
  vtkNew<vtkTextActor> scale_text;
  vtkNew<vtkTextActor> north_text;
  vtkNew<vtkCallbackCommand> before_render;
  ScaleBar scale;
  double extent = 1.0;  ///< the grid's larger side (m)
  // The pick marker: a sphere on the picked cell and a pin above it.
  bool has_pick = false;
  std::array<double, 3> pick_point{};  ///< world x, y (m) and bed z (m, not exaggerated)
  vtkNew<vtkSphereSource> marker_sphere;
  vtkNew<vtkPolyDataMapper> marker_mapper;
  vtkNew<vtkActor> marker_actor;
  vtkNew<vtkLineSource> pin;
  vtkNew<vtkPolyDataMapper> pin_mapper;
  vtkNew<vtkActor> pin_actor;
  // The picked cell's time series: a vtkChartXY in its own renderer at the left edge.
  vtkNew<vtkRenderer> chart_renderer;
  vtkNew<vtkContextActor> chart_actor;
  vtkNew<vtkChartXY> chart;
  vtkNew<vtkTable> series;
  vtkNew<vtkCellPicker> picker;
  vtkNew<vtkStaticCellLocator> locator;
  bool locator_stale = true;
  bool water_on = true;
  bool has_water_field = false;
  bool geometry_built = false;
  std::vector<float> coarse_bed;  ///< the drawn bed (m), per vertex
};

Scene::Scene(ViewData& data, const SceneOptions& o)
    : data_(data), impl_(std::make_unique<Impl>()), options_(o) {
  auto& m = *impl_;
  data_.field(o.field);  // unknown -> Error
  field_ = o.field;
  m.water_on = o.water;
  time_index_ = std::min(o.time_index, data_.times().size() - 1);
  water_threshold_ = o.water_threshold;
  const Grid& grid = data_.grid();
  lod_ = Lod::for_budget(grid.nx, grid.ny, o.max_cells);
  m.frame = WorldFrame::for_grid(grid);
  m.has_water_field = data_.has_field("water_depth");
  exaggeration_ = o.exaggeration > 0.0 ? o.exaggeration : auto_exaggeration(grid, data_.bed(0));

  m.window->SetSize(o.width, o.height);
  m.window->SetOffScreenRendering(o.offscreen ? 1 : 0);
  m.window->SetWindowName(("erodem view " + data_.path()).c_str());
  m.window->AddRenderer(m.renderer);
  m.renderer->SetBackground(0.12, 0.13, 0.16);
  m.renderer->SetBackground2(0.45, 0.52, 0.62);
  m.renderer->GradientBackgroundOn();

  // Light: a sun from the north-west, 45 degrees up (relief shading as on maps), and a dim
  // headlight so that slopes facing away never go black.
  vtkNew<vtkLight> sun;
  sun->SetLightTypeToSceneLight();
  sun->SetPositional(false);
  sun->SetPosition(-1.0, 1.0, 1.4);
  sun->SetFocalPoint(0.0, 0.0, 0.0);
  sun->SetIntensity(0.85);
  vtkNew<vtkLight> head;
  head->SetLightTypeToHeadlight();
  head->SetIntensity(0.3);
  m.renderer->AddLight(sun);
  m.renderer->AddLight(head);

  m.terrain_mapper->SetInputData(m.terrain);
  m.terrain_mapper->SetLookupTable(m.lut);
  m.terrain_mapper->SetScalarModeToUsePointData();
  m.terrain_mapper->UseLookupTableScalarRangeOn();
  m.terrain_mapper->InterpolateScalarsBeforeMappingOn();
  m.terrain_actor->SetMapper(m.terrain_mapper);
  m.terrain_actor->GetProperty()->SetAmbient(0.12);
  m.terrain_actor->GetProperty()->SetDiffuse(0.88);
  m.terrain_actor->GetProperty()->SetSpecular(0.0);
  m.renderer->AddActor(m.terrain_actor);

  if (!o.offscreen) {
    const Lod coarse = Lod::for_budget(grid.nx, grid.ny, o.interaction_cells);
    if (coarse.factor > lod_.factor) m.interaction_lod = coarse;
  }
  m.interaction_mapper->SetInputData(m.interaction_terrain);
  m.interaction_mapper->SetLookupTable(m.lut);
  m.interaction_mapper->SetScalarModeToUsePointData();
  m.interaction_mapper->UseLookupTableScalarRangeOn();
  m.interaction_mapper->InterpolateScalarsBeforeMappingOn();
  m.interaction_actor->SetMapper(m.interaction_mapper);
  m.interaction_actor->SetProperty(m.terrain_actor->GetProperty());
  m.interaction_actor->PickableOff();
  m.interaction_actor->VisibilityOff();
  m.renderer->AddActor(m.interaction_actor);

  // Water: per-vertex RGBA (kWaterRgb, opacity by depth).
  m.water_mapper->SetInputData(m.water);
  m.water_mapper->ScalarVisibilityOn();
  m.water_mapper->SetScalarModeToUsePointData();
  m.water_mapper->SetColorModeToDirectScalars();
  m.water_actor->SetMapper(m.water_mapper);
  m.water_actor->GetProperty()->SetAmbient(0.25);
  m.water_actor->GetProperty()->SetDiffuse(0.75);
  m.water_actor->GetProperty()->SetSpecular(0.3);
  m.water_actor->GetProperty()->SetSpecularPower(30.0);
  m.water_actor->PickableOff();
  m.water_actor->SetVisibility(m.has_water_field && m.water_on);
  m.renderer->AddActor(m.water_actor);

  m.bar->SetLookupTable(m.lut);
  m.bar->SetNumberOfLabels(5);
  m.bar->SetMaximumWidthInPixels(130);
  m.bar->SetPosition(0.84, 0.12);
  m.bar->SetWidth(0.14);
  m.bar->SetHeight(0.75);
  m.bar->UnconstrainedFontSizeOn();
  m.bar->GetTitleTextProperty()->SetFontSize(16);
  m.bar->GetLabelTextProperty()->SetFontSize(14);
  m.bar->GetAnnotationTextProperty()->SetFontSize(14);
  m.bar->SetAboveRangeAnnotation(nullptr);
  m.bar->SetBelowRangeAnnotation(nullptr);
  m.renderer->AddActor2D(m.bar);

  m.overlay_mapper->SetInputData(m.overlay);
  m.overlay_actor->SetMapper(m.overlay_mapper);
  m.overlay_actor->GetProperty()->SetColor(1.0, 1.0, 1.0);
  m.overlay_actor->GetProperty()->SetLineWidth(2.0);
  m.renderer->AddActor2D(m.overlay_actor);
  for (vtkTextActor* t : {m.scale_text.Get(), m.north_text.Get()}) {
    t->GetTextProperty()->SetFontSize(15);
    t->GetTextProperty()->SetColor(1.0, 1.0, 1.0);
    t->GetTextProperty()->SetJustificationToCentered();
    t->GetTextProperty()->SetBold(true);
    m.renderer->AddActor2D(t);
  }
  m.north_text->SetInput("N");
  m.before_render->SetCallback([](vtkObject*, unsigned long, void* scene, void*) {
    static_cast<Scene*>(scene)->update_overlays();
  });
  m.before_render->SetClientData(this);
  m.renderer->AddObserver(vtkCommand::StartEvent, m.before_render);
  m.extent = std::max(grid.nx * grid.dx[grid.ny / 2], grid.ny * grid.dy[grid.ny / 2]);

  m.marker_sphere->SetThetaResolution(24);
  m.marker_sphere->SetPhiResolution(12);
  m.marker_mapper->SetInputConnection(m.marker_sphere->GetOutputPort());
  m.marker_actor->SetMapper(m.marker_mapper);
  m.pin_mapper->SetInputConnection(m.pin->GetOutputPort());
  m.pin_actor->SetMapper(m.pin_mapper);
  for (vtkActor* a : {m.marker_actor.Get(), m.pin_actor.Get()}) {
    a->GetProperty()->SetColor(kMarkerRgb[0], kMarkerRgb[1], kMarkerRgb[2]);
    a->GetProperty()->SetAmbient(0.5);
    a->PickableOff();
    a->VisibilityOff();
    m.renderer->AddActor(a);
  }
  m.pin_actor->GetProperty()->SetLineWidth(3.0);
  m.pin_actor->GetProperty()->LightingOff();

  m.status->GetTextProperty()->SetFontSize(16);
  m.status->GetTextProperty()->SetColor(1.0, 1.0, 1.0);
  m.status->GetTextProperty()->SetVerticalJustificationToTop();
  m.status->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  m.status->SetPosition(0.01, 0.985);
  m.renderer->AddActor2D(m.status);
  // The pick panel: the picked cell's values on a dark, framed background.
  m.pick_text->GetTextProperty()->SetFontSize(14);
  m.pick_text->GetTextProperty()->SetColor(1.0, 1.0, 0.85);
  m.pick_text->GetTextProperty()->SetBackgroundColor(0.0, 0.0, 0.0);
  m.pick_text->GetTextProperty()->SetBackgroundOpacity(0.65);
  m.pick_text->GetTextProperty()->FrameOn();
  m.pick_text->GetTextProperty()->SetFrameColor(kMarkerRgb[0], kMarkerRgb[1], kMarkerRgb[2]);
  m.pick_text->SetDisplayPosition(10, 10);
  m.renderer->AddActor2D(m.pick_text);

  // The time-series chart of the picked cell: hidden until a pick (of a file with several
  // snapshots); on a light panel at the left edge, above the pick panel.
  m.chart_renderer->SetViewport(0.0, 0.42, 0.36, 0.82);
  m.chart_renderer->SetBackground(0.96, 0.96, 0.94);
  m.chart_renderer->InteractiveOff();
  m.chart_renderer->DrawOff();
  m.chart_actor->GetScene()->AddItem(m.chart);
  m.chart_renderer->AddActor(m.chart_actor);
  m.chart->SetShowLegend(true);
  m.chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::LEFT);
  m.chart->GetLegend()->SetVerticalAlignment(vtkChartLegend::TOP);
  m.chart->GetAxis(vtkAxis::BOTTOM)->SetTitle("t (s)");
  m.chart->GetAxis(vtkAxis::LEFT)->SetTitle("depth (m), speed (m/s)");
  m.chart->GetAxis(vtkAxis::RIGHT)->SetTitle("bed (m)");
  m.window->AddRenderer(m.chart_renderer);

  m.picker->PickFromListOn();
  m.picker->AddPickList(m.terrain_actor);

  rebuild_geometry();
  update_colors();
  set_exaggeration(exaggeration_);
  reset_camera(o.top_view);
}

Scene::~Scene() = default;

vtkRenderWindow* Scene::window() {
  return impl_->window;
}
vtkRenderer* Scene::renderer() {
  return impl_->renderer;
}
bool Scene::water_visible() const {
  return impl_->water_on && impl_->has_water_field;
}
ColorMap Scene::color_map() const {
  return impl_->map;
}
std::array<double, 2> Scene::color_limits() const {
  return impl_->limits;
}
std::array<bool, 2> Scene::clipped() const {
  return impl_->clipped;
}
ScaleBar Scene::scale_bar() const {
  return impl_->scale;
}

namespace {

/// Builds the terrain mesh of the full-resolution `bed` (m) drawn at `lod` into `poly`:
/// a vertex per coarse cell centre, normals, two triangles per quad of valid vertices.
/// Returns the drawn (decimated) bed.
std::vector<float> build_terrain_mesh(const Grid& grid, const WorldFrame& frame, const Lod& lod,
                                      const std::vector<float>& bed, vtkPolyData* poly) {
  std::vector<float> z = decimate(bed, lod, Reduce::mean);
  const int nx = lod.coarse_nx, ny = lod.coarse_ny;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToFloat();
  points->SetNumberOfPoints(static_cast<vtkIdType>(nx) * ny);
  std::vector<double> wx(nx), wy(ny);
  for (int i = 0; i < nx; ++i)
    wx[i] = frame.to_world(cell_point(grid, lod.fine_col(i), 0.0)[0], frame.y0)[0];
  for (int j = 0; j < ny; ++j)
    wy[j] = frame.to_world(frame.x0, cell_point(grid, 0.0, lod.fine_row(j))[1])[1];
  vtkNew<vtkFloatArray> normals;
  normals->SetNumberOfComponents(3);
  normals->SetNumberOfTuples(static_cast<vtkIdType>(nx) * ny);
  normals->SetName("normals");
  // Slope along one axis from the vertex's valid neighbours (0 when it has none).
  const auto slope = [](double zc, double zlo, double zhi, double clo, double chi,
                        double c) -> double {
    const bool l = std::isfinite(zlo), h = std::isfinite(zhi);
    if (l && h) return (zhi - zlo) / (chi - clo);
    if (h) return (zhi - zc) / (chi - c);
    if (l) return (zc - zlo) / (c - clo);
    return 0.0;
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const auto k = vid(i, j, nx);
      const double zc = z[k];
      const bool ok = std::isfinite(zc);
      points->SetPoint(static_cast<vtkIdType>(k), wx[i], wy[j], ok ? zc : 0.0);
      double n[3] = {0.0, 0.0, 1.0};
      if (ok) {
        const double zw = i > 0 ? z[k - 1] : NAN, ze = i + 1 < nx ? z[k + 1] : NAN;
        const double zn = j > 0 ? z[k - nx] : NAN, zs = j + 1 < ny ? z[k + nx] : NAN;
        const double gx =
            slope(zc, zw, ze, i > 0 ? wx[i - 1] : 0.0, i + 1 < nx ? wx[i + 1] : 0.0, wx[i]);
        const double gy =
            slope(zc, zs, zn, j + 1 < ny ? wy[j + 1] : 0.0, j > 0 ? wy[j - 1] : 0.0, wy[j]);
        const double len = std::sqrt(gx * gx + gy * gy + 1.0);
        n[0] = -gx / len;
        n[1] = -gy / len;
        n[2] = 1.0 / len;
      }
      normals->SetTuple(static_cast<vtkIdType>(k), n);
    }
  poly->SetPoints(points);
  poly->GetPointData()->SetNormals(normals);
  poly->SetPolys(quad_triangles(nx, ny, [&](auto a, auto b, auto c, auto d) {
    return std::isfinite(z[a]) && std::isfinite(z[b]) && std::isfinite(z[c]) && std::isfinite(z[d]);
  }));
  poly->Modified();
  return z;
}

/// Sets the point scalars of a mesh drawn at `lod` from the full-resolution `values`.
void set_point_scalars(vtkPolyData* poly, const std::string& name, const std::vector<float>& values,
                       const Lod& lod, Reduce reduce) {
  const std::vector<float> v = decimate(values, lod, reduce);
  vtkNew<vtkFloatArray> scalars;
  scalars->SetName(name.c_str());
  scalars->SetNumberOfTuples(static_cast<vtkIdType>(v.size()));
  std::copy(v.begin(), v.end(), scalars->GetPointer(0));
  poly->GetPointData()->SetScalars(scalars);
  poly->Modified();
}

}  // namespace

void Scene::rebuild_geometry() {
  auto& m = *impl_;
  const Grid& grid = data_.grid();
  const int nx = lod_.coarse_nx, ny = lod_.coarse_ny;
  const bool terrain_changes = !m.geometry_built || data_.bed_varies();
  if (terrain_changes) {
    const std::vector<float>& bed = data_.bed(time_index_);
    m.coarse_bed = build_terrain_mesh(grid, m.frame, lod_, bed, m.terrain);
    if (m.interaction_lod.factor > lod_.factor)
      build_terrain_mesh(grid, m.frame, m.interaction_lod, bed, m.interaction_terrain);
    m.locator_stale = true;
    m.geometry_built = true;
  }
  if (m.has_water_field) {
    const std::vector<float> depth =
        decimate(data_.values("water_depth", time_index_), lod_, Reduce::mean);
    const auto& z = m.coarse_bed;
    const double thr = water_threshold_;
    const auto wet = [&](std::size_t k) { return std::isfinite(depth[k]) && depth[k] > thr; };
    vtkNew<vtkPoints> points;
    points->SetDataTypeToFloat();
    points->SetNumberOfPoints(static_cast<vtkIdType>(nx) * ny);
    vtkNew<vtkUnsignedCharArray> rgba;
    rgba->SetNumberOfComponents(4);
    rgba->SetNumberOfTuples(static_cast<vtkIdType>(nx) * ny);
    rgba->SetName("water_rgba");
    auto* terrain_points = m.terrain->GetPoints();
    for (vtkIdType k = 0; k < static_cast<vtkIdType>(nx) * ny; ++k) {
      double p[3];
      terrain_points->GetPoint(k, p);
      const auto ks = static_cast<std::size_t>(k);
      // Dry corners of a wet quad are transparent: the shore fades out.
      double alpha = 0.0;
      if (wet(ks)) {
        p[2] += depth[ks];
        alpha = std::min(kWaterAlphaMax,
                         kWaterAlphaMin + (kWaterAlphaMax - kWaterAlphaMin) * (depth[ks] - thr) /
                                              std::max(1e-6, kWaterOpaqueDepth - thr));
      }
      points->SetPoint(k, p);
      const double c[4] = {255.0 * kWaterRgb[0], 255.0 * kWaterRgb[1], 255.0 * kWaterRgb[2],
                           255.0 * alpha};
      rgba->SetTuple(k, c);
    }
    m.water->SetPoints(points);
    m.water->GetPointData()->SetScalars(rgba);
    m.water->SetPolys(quad_triangles(nx, ny, [&](auto a, auto b, auto c, auto d) {
      return std::isfinite(z[a]) && std::isfinite(z[b]) && std::isfinite(z[c]) &&
             std::isfinite(z[d]) && (wet(a) || wet(b) || wet(c) || wet(d));
    }));
    m.water->Modified();
  }
}

void Scene::update_colors() {
  auto& m = *impl_;
  const ViewField& f = data_.field(field_);
  const std::vector<float>& full = data_.values(field_, time_index_);
  // --cmap and --clim are for the field they were given with; the others keep their own.
  const bool asked = field_ == options_.field;
  m.map = asked && options_.cmap ? *options_.cmap : f.map;
  if (asked && options_.clim)
    m.limits = *options_.clim;
  else if (options_.rescale)
    m.limits = color_range(m.map, full);
  else
    m.limits = data_.held_color_range(field_, m.map);
  const auto range = m.limits;
  const Reduce reduce = m.map == ColorMap::classes ? Reduce::sample : Reduce::mean;
  set_point_scalars(m.terrain, f.name, full, lod_, reduce);
  if (m.interaction_lod.factor > lod_.factor)
    set_point_scalars(m.interaction_terrain, f.name, full, m.interaction_lod, reduce);

  m.lut->ResetAnnotations();
  m.clipped = {false, false};
  if (m.map == ColorMap::classes) {
    const auto& names = terrain_class_names();
    const int n = static_cast<int>(names.size());
    m.lut->SetNumberOfTableValues(n);
    m.lut->SetTableRange(-0.5, n - 0.5);
    for (int k = 0; k < n; ++k) {
      const auto c = color_stops(ColorMap::classes)[k].rgb;
      m.lut->SetTableValue(k, c[0], c[1], c[2], 1.0);
      m.lut->SetAnnotation(vtkVariant(static_cast<double>(k)), names[k]);
    }
    m.lut->UseAboveRangeColorOff();
    m.lut->UseBelowRangeColorOff();
    m.bar->SetNumberOfLabels(0);
    m.bar->DrawAnnotationsOn();
    // The names beside their swatches, not at the ends of leader lines.
    m.bar->SetAnnotationLeaderPadding(4.0);
    m.bar->SetTitle("terrain class");
  } else {
    const int n = 256;
    m.lut->SetNumberOfTableValues(n);
    m.lut->SetTableRange(range[0], range[1]);
    for (int k = 0; k < n; ++k) {
      const auto c = color_at(m.map, k / double(n - 1));
      m.lut->SetTableValue(k, c[0], c[1], c[2], 1.0);
    }
    // Values beyond the range keep the end colours on the terrain; the bar marks them
    // with a triangle (ClipBarActor) at the end they pass.
    const auto lo = color_at(m.map, 0.0), hi = color_at(m.map, 1.0);
    m.lut->SetBelowRangeColor(lo[0], lo[1], lo[2], 1.0);
    m.lut->SetAboveRangeColor(hi[0], hi[1], hi[2], 1.0);
    for (float v : full)
      if (std::isfinite(v)) {
        if (v < range[0]) m.clipped[0] = true;
        if (v > range[1]) m.clipped[1] = true;
      }
    m.lut->SetUseBelowRangeColor(m.clipped[0]);
    m.lut->SetUseAboveRangeColor(m.clipped[1]);
    m.bar->SetNumberOfLabels(5);
    m.bar->DrawAnnotationsOff();
    m.bar->SetTitle((f.name + (f.units.empty() ? "" : " (" + f.units + ")")).c_str());
  }
  m.bar->SetDrawBelowRangeSwatch(m.clipped[0]);
  m.bar->SetDrawAboveRangeSwatch(m.clipped[1]);
  m.bar->Modified();
  m.lut->SetNanColor(0.45, 0.45, 0.45, 1.0);
  m.lut->Build();
  m.lut->Modified();
  update_status();
}

void Scene::update_status() {
  auto& m = *impl_;
  const ViewField& f = data_.field(field_);
  const auto& times = data_.times();
  std::string lod = lod_.factor == 1
                        ? fmt::format("{} x {} cells", lod_.nx, lod_.ny)
                        : fmt::format("{} x {} cells drawn 1:{} as {} x {}", lod_.nx, lod_.ny,
                                      lod_.factor, lod_.coarse_nx, lod_.coarse_ny);
  const std::string name = std::filesystem::path(data_.path()).filename().string();
  const std::string units = f.units.empty() || f.units == "1" ? "" : " (" + f.units + ")";
  m.status->SetInput(fmt::format("{}   {}{}   t = {:g} s (snapshot {} of 0..{})   z x{:.3g}   {}",
                                 name, f.name, units, times[time_index_], time_index_,
                                 times.size() - 1, exaggeration_, lod)
                         .c_str());
}

void Scene::set_field(const std::string& name) {
  data_.field(name);
  field_ = name;
  update_colors();
}

void Scene::set_time_index(std::size_t index) {
  index = std::min(index, data_.times().size() - 1);
  if (index == time_index_) return;
  time_index_ = index;
  rebuild_geometry();
  update_colors();
}

void Scene::set_exaggeration(double e) {
  auto& m = *impl_;
  exaggeration_ = std::clamp(std::isfinite(e) ? e : 1.0, 0.01, 1000.0);
  m.terrain_actor->SetScale(1.0, 1.0, exaggeration_);
  m.interaction_actor->SetScale(1.0, 1.0, exaggeration_);
  m.water_actor->SetScale(1.0, 1.0, exaggeration_);
  place_marker();
  update_status();
}

void Scene::set_water_visible(bool visible) {
  impl_->water_on = visible;
  impl_->water_actor->SetVisibility(visible && impl_->has_water_field && !impl_->interacting);
}

bool Scene::has_interaction_lod() const {
  return impl_->interaction_lod.factor > lod_.factor;
}

void Scene::set_interacting(bool interacting) {
  auto& m = *impl_;
  if (!has_interaction_lod() || interacting == m.interacting) return;
  m.interacting = interacting;
  m.terrain_actor->SetVisibility(!interacting);
  m.interaction_actor->SetVisibility(interacting);
  set_water_visible(m.water_on);
}

void Scene::reset_camera(bool top_view) {
  auto& m = *impl_;
  auto* cam = m.renderer->GetActiveCamera();
  double b[6];
  m.terrain_actor->GetBounds(b);
  const double cx = 0.5 * (b[0] + b[1]), cy = 0.5 * (b[2] + b[3]), cz = 0.5 * (b[4] + b[5]);
  cam->SetFocalPoint(cx, cy, cz);
  if (top_view) {
    cam->SetPosition(cx, cy, cz + 1.0);
    cam->SetViewUp(0.0, 1.0, 0.0);
  } else {
    const double elevation = 40.0 * M_PI / 180.0;  // looking down from the south
    cam->SetPosition(cx, cy - std::cos(elevation), cz + std::sin(elevation));
    cam->SetViewUp(0.0, 0.0, 1.0);
  }
  m.renderer->ResetCamera();
  cam->Zoom(top_view ? 1.05 : 1.3);
  m.renderer->ResetCameraClippingRange();
}

void Scene::place_marker() {
  auto& m = *impl_;
  m.marker_actor->SetVisibility(m.has_pick);
  m.pin_actor->SetVisibility(m.has_pick);
  if (!m.has_pick) return;
  const double r = 0.02 * m.extent;
  const double x = m.pick_point[0], y = m.pick_point[1], z = m.pick_point[2] * exaggeration_;
  m.marker_sphere->SetCenter(x, y, z);
  m.marker_sphere->SetRadius(r);
  m.pin->SetPoint1(x, y, z);
  m.pin->SetPoint2(x, y, z + 8.0 * r);
}

void Scene::show_series(int col, int row) {
  auto& m = *impl_;
  m.chart->ClearPlots();
  m.chart_renderer->SetDraw(false);
  if (data_.times().size() < 2) return;
  struct Curve {
    const char* field;
    const char* label;
    std::array<unsigned char, 3> rgb;
    int corner;  // 0: left axis, 1: right axis
  };
  std::vector<Curve> curves;
  for (const Curve& c :
       {Curve{"water_depth", "depth (m)", {13, 115, 255}, 0},
        Curve{"speed", "speed (m/s)", {230, 120, 20}, 0}, Curve{"bed", "bed (m)", {90, 60, 40}, 1}})
    if (data_.has_field(c.field)) curves.push_back(c);
  if (curves.empty()) return;
  std::vector<std::string> names;
  for (const auto& c : curves) names.emplace_back(c.field);
  const auto series = data_.cell_series(col, row, names);
  m.series->Initialize();
  vtkNew<vtkDoubleArray> t;
  t->SetName("t (s)");
  for (const auto& s : series) t->InsertNextValue(s.time);
  m.series->AddColumn(t);
  for (std::size_t k = 0; k < curves.size(); ++k) {
    vtkNew<vtkDoubleArray> v;
    v->SetName(curves[k].label);
    for (const auto& s : series) v->InsertNextValue(s.values[k].second);
    m.series->AddColumn(v);
    vtkPlot* plot = m.chart->AddPlot(vtkChart::LINE);
    plot->SetInputData(m.series, 0, static_cast<vtkIdType>(k + 1));
    plot->SetColor(curves[k].rgb[0], curves[k].rgb[1], curves[k].rgb[2], 255);
    plot->SetWidth(2.5);
    m.chart->SetPlotCorner(plot, curves[k].corner);
  }
  m.chart->SetTitle(fmt::format("cell (col {}, row {})", col, row));
  m.chart->RecalculateBounds();
  m.chart_renderer->SetDraw(true);
}

void Scene::update_overlays() {
  auto& m = *impl_;
  auto* ren = m.renderer.Get();
  const int* size = ren->GetSize();
  const double w = size[0], h = size[1];
  if (w < 2 || h < 2) return;
  auto* cam = ren->GetActiveCamera();
  double f[3], up[3], dop[3];
  cam->GetFocalPoint(f);
  cam->GetViewUp(up);
  cam->GetDirectionOfProjection(dop);
  const auto display = [&](double x, double y, double z) {
    ren->SetWorldPoint(x, y, z, 1.0);
    ren->WorldToDisplay();
    double d[3];
    ren->GetDisplayPoint(d);
    return std::array<double, 2>{d[0], d[1]};
  };
  // The screen's horizontal on the ground: direction of projection x view up, made level.
  double right[3] = {dop[1] * up[2] - dop[2] * up[1], dop[2] * up[0] - dop[0] * up[2], 0.0};
  double len = std::hypot(right[0], right[1]);
  if (!(len > 1e-9)) right[0] = 1.0, right[1] = 0.0, len = 1.0;
  const double probe = 0.01 * m.extent;
  const auto c = display(f[0], f[1], f[2]);
  const auto e = display(f[0] + probe * right[0] / len, f[1] + probe * right[1] / len, f[2]);
  const auto n = display(f[0], f[1] + probe, f[2]);
  const double px_per_m = std::hypot(e[0] - c[0], e[1] - c[1]) / probe;
  if (!(px_per_m > 0.0) || !std::isfinite(px_per_m)) return;
  m.scale.metres = nice_length(0.2 * w / px_per_m);
  m.scale.pixels = m.scale.metres * px_per_m;
  m.scale.north_degrees = std::atan2(n[0] - c[0], n[1] - c[1]) * 180.0 / M_PI;

  vtkNew<vtkPoints> pts;
  vtkNew<vtkCellArray> polys, lines;
  const auto add = [&](double x, double y) { return pts->InsertNextPoint(x, y, 0.0); };
  // Scale bar, bottom right: a 6-pixel bar with ticks, its length above.
  const double x1 = w - 20.0, x0 = x1 - m.scale.pixels, y0 = 22.0;
  const vtkIdType q[4] = {add(x0, y0), add(x1, y0), add(x1, y0 + 6.0), add(x0, y0 + 6.0)};
  polys->InsertNextCell(4, q);
  for (double x : {x0, 0.5 * (x0 + x1), x1}) {
    const vtkIdType t[2] = {add(x, y0 - 4.0), add(x, y0 + 10.0)};
    lines->InsertNextCell(2, t);
  }
  m.scale_text->SetInput(m.scale.metres >= 1000.0
                             ? fmt::format("{:g} km", m.scale.metres / 1000.0).c_str()
                             : fmt::format("{:g} m", m.scale.metres).c_str());
  m.scale_text->SetDisplayPosition(static_cast<int>(0.5 * (x0 + x1)), static_cast<int>(y0 + 12.0));
  // North arrow, left of the scale bar: a shaft and a head along north on screen, "N" at
  // its tip.
  const double a = m.scale.north_degrees * M_PI / 180.0, L = 36.0;
  const double ux = std::sin(a), uy = std::cos(a), cx = x0 - 35.0, cy = y0 + 16.0;
  const double tx = cx + 0.5 * L * ux, ty = cy + 0.5 * L * uy;
  const vtkIdType shaft[2] = {add(cx - 0.5 * L * ux, cy - 0.5 * L * uy), add(tx, ty)};
  lines->InsertNextCell(2, shaft);
  const vtkIdType head[3] = {add(tx, ty), add(tx - 14.0 * ux - 7.0 * uy, ty - 14.0 * uy + 7.0 * ux),
                             add(tx - 14.0 * ux + 7.0 * uy, ty - 14.0 * uy - 7.0 * ux)};
  polys->InsertNextCell(3, head);
  m.north_text->SetDisplayPosition(static_cast<int>(tx + 16.0 * ux),
                                   static_cast<int>(ty + 16.0 * uy - 8.0));
  m.overlay->SetPoints(pts);
  m.overlay->SetPolys(polys);
  m.overlay->SetLines(lines);
  m.overlay->Modified();
}

void Scene::orbit(double degrees) {
  impl_->renderer->GetActiveCamera()->Azimuth(degrees);
  impl_->renderer->ResetCameraClippingRange();
}

void Scene::render() {
  impl_->window->Render();
}

std::optional<std::array<double, 2>> Scene::display_of(double x, double y) {
  const Grid& grid = data_.grid();
  int col = 0, row = 0;
  if (!grid.locate(x, y, col, row)) return std::nullopt;
  const double z = data_.bed(time_index_)[static_cast<std::size_t>(row) * grid.nx + col];
  if (!std::isfinite(z)) return std::nullopt;
  const auto w = impl_->frame.to_world(x, y);
  auto* ren = impl_->renderer.Get();
  ren->SetWorldPoint(w[0], w[1], z * exaggeration_, 1.0);
  ren->WorldToDisplay();
  double d[3];
  ren->GetDisplayPoint(d);
  return std::array<double, 2>{d[0], d[1]};
}

std::optional<PickResult> Scene::pick(double px, double py) {
  auto& m = *impl_;
  if (m.locator_stale) {
    m.picker->RemoveAllLocators();
    m.locator->SetDataSet(m.terrain);
    m.locator->BuildLocator();
    m.picker->AddLocator(m.locator);
    m.locator_stale = false;
  }
  if (!m.picker->Pick(px, py, 0.0, m.renderer) || m.picker->GetCellId() < 0) return std::nullopt;
  PickResult r;
  m.picker->GetPickPosition(r.world.data());
  const auto p = m.frame.to_crs(r.world[0], r.world[1]);
  const Grid& grid = data_.grid();
  int col = 0, row = 0;
  if (!grid.locate(p[0], p[1], col, row)) {
    // On the outer half cell the mesh (through cell centres) cannot reach: clamp.
    const auto& t = grid.georef.transform;
    col = std::clamp(static_cast<int>(std::floor((p[0] - t[0]) / t[1])), 0, grid.nx - 1);
    row = std::clamp(static_cast<int>(std::floor((p[1] - t[3]) / t[5])), 0, grid.ny - 1);
  }
  r.cell = data_.cell_values(col, row, time_index_);
  m.pick_text->SetInput(describe_pick(data_, r.cell).c_str());
  m.has_pick = true;
  m.pick_point = {r.world[0], r.world[1], r.world[2] / exaggeration_};
  place_marker();
  show_series(col, row);
  return r;
}

void Scene::write_png(const std::string& path) {
  auto& m = *impl_;
  m.window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->ShouldRerenderOff();  // just rendered
  grab->SetInput(m.window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  const std::filesystem::path target(path);
  const std::filesystem::path tmp =
      target.parent_path() / fmt::format(".{}.{}.partial", target.filename().string(), getpid());
  vtkNew<vtkPNGWriter> writer;
  writer->SetCompressionLevel(9);
  writer->SetFileName(tmp.string().c_str());
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  std::error_code ec;
  if (writer->GetErrorCode() != 0 || !std::filesystem::exists(tmp, ec)) {
    std::filesystem::remove(tmp, ec);
    throw Error(ExitCode::io, path + ": could not write the PNG image");
  }
  std::filesystem::rename(tmp, target, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw Error(ExitCode::cant_create, path + ": could not create the file: " + ec.message());
  }
}

std::string describe_pick(const ViewData& data, const CellValues& cell) {
  std::string s = fmt::format("cell (col {}, row {})  ", cell.col, cell.row);
  if (data.grid().georef.is_geographic)
    s += fmt::format("lon {:.6f}, lat {:.6f}", cell.x, cell.y);
  else
    s += fmt::format("x {:.2f}, y {:.2f}", cell.x, cell.y);
  s += fmt::format("  t = {:g} s", cell.time);
  for (const auto& [name, v] : cell.values) {
    std::string units;
    for (const auto& f : data.fields())
      if (f.name == name) units = f.units;
    if (name == "terrain_class" && std::isfinite(v))
      s += fmt::format("\n{} = {}", name, terrain_class_names().at(static_cast<std::size_t>(v)));
    else
      s += fmt::format("\n{} = {} {}", name, format_value(v), units == "1" ? "" : units);
  }
  return s;
}

std::string pick_json(const ViewData& data, const CellValues& cell) {
  std::string s = fmt::format("{{\"col\": {}, \"row\": {}, \"x\": {}, \"y\": {}, ", cell.col,
                              cell.row, json_number(cell.x), json_number(cell.y));
  if (data.grid().georef.is_geographic)
    s += fmt::format("\"lon\": {}, \"lat\": {}, ", json_number(cell.x), json_number(cell.y));
  s += fmt::format("\"time\": {}, \"values\": {{", json_number(cell.time));
  bool first = true;
  for (const auto& [name, v] : cell.values) {
    s += fmt::format("{}\"{}\": {}", first ? "" : ", ", name, json_number(v));
    first = false;
  }
  return s + "}}";
}

}  // namespace erodem::viz
