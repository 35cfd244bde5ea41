// erodem — cross-sections ([[section]]) and outlets ([[outlet]]): the grid faces each one
// measures, found once on the host, and what crossed them, summed every step from the
// backends' per-face values (Backend::set_faces, StepResult::face_water, face_sediment).
#pragma once

#include <string>
#include <vector>

#include "erodem/backend.hpp"
#include "erodem/grid.hpp"
#include "erodem/params.hpp"

namespace erodem {

/// The faces of every section and outlet, sections first, each in config order.
struct SectionLayout {
  std::vector<std::string> names;  ///< [section]
  std::vector<bool> outlet;        ///< [section]: an outlet ([[outlet]]), not a [[section]]
  std::vector<Face> faces;         ///< every measured face
  std::vector<int> section;        ///< [face]: the section or outlet it belongs to
  std::vector<double> sign;        ///< [face]: +1 or -1, the face's positive way (east/south)
                                   ///< as the section counts it
};

/// The faces of params.section and params.outlet on the terrain's grid:
/// - a section counts positive what crosses its polyline from left to right, walking from
///   its first vertex to its last (map coordinates, x east, y north). A face between two
///   cells is crossed when the segment joining their centres crosses a segment of the line
///   (the centres on different sides of its line, the crossing within [0, 1) of the segment,
///   [0, 1] for the last), so the faces form the staircase between the cells on either side,
///   and a closed line gives exactly the faces between the cells inside and outside it;
/// - an outlet counts positive what leaves the grid: through the faces of a whole edge
///   (edge = "north", ...), or the faces the active cell under `point` shares with the grid's
///   edge or nodata cells. Only active cells' faces: the ledger's boundary_out.
/// Errors (ExitCode::config) name the key: a vertex or point outside the grid, a section that
/// crosses no face, a point on a nodata cell or with no face to the outside.
SectionLayout layout_sections(const Terrain& terrain, const Params& params);

/// A section's or outlet's measure after a step.
struct SectionState {
  double discharge = 0.0;        ///< m^3/s through it in the latest step (the water update's)
  double sediment_flux = 0.0;    ///< m^3/s of solid sediment in the latest step (transport's)
  double volume = 0.0;           ///< m^3 through it since the run (or restart) began
  double sediment_volume = 0.0;  ///< m^3 of solid since the run (or restart) began
  double peak_discharge = 0.0;   ///< the largest discharge of a step so far (m^3/s)
  double peak_time = 0.0;        ///< the end of that step (s)
};

}  // namespace erodem
