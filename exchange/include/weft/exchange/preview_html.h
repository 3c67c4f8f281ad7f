#pragma once
// weft export -o X.html: one self-contained page that previews the glTF material fitted to a table
// (gltf_material.h) on a cushion and a cloth draped over a sphere, lit by an environment and
// orbitable with the mouse, beside the table's own in-plane curves and the fit's figures. The page
// fetches nothing: the .glb (the one weft export -o X.glb writes, with the preview's two meshes
// instead of the sample quad) is in it as base64, the viewer is three.js (pinned in
// exchange/viewer/package-lock.json, installed by scripts/install-viewer.sh) inlined as data: URL
// modules under an import map, and the curves are an inline SVG drawn here.
#include <filesystem>
#include <string>
#include <vector>

#include "weft/core/install_paths.h"
#include "weft/exchange/export_report.h"
#include "weft/exchange/gltf_material.h"
#include "weft/materials/bsdf_table.h"

namespace weft {

// The viewer's JavaScript modules, read from exchange/viewer (the source tree or an installed
// share/weft): three.js's build and the example modules the page imports, and the page's own
// script (exchange/viewer/preview.js). Each is keyed by the name the page imports it by.
struct ViewerModule {
  std::string specifier;  // "three", "weft/GLTFLoader", ... ; "" for the page's own script
  std::string source;
};
// Looked for under 'roots' (install_paths.h: an installed share/weft, then the source tree).
// weft::Error naming the first missing file and how to install it (scripts/install-viewer.sh).
std::vector<ViewerModule> load_viewer_modules(
    const std::vector<std::filesystem::path>& roots = bundled_data_roots());

// The in-plane radiance coefficient beta = pi f of the table (materials/table_inplane.h) at each
// incidence of 'incidences_deg', views -90..90 degrees (> 0 on the mirror side), one line per
// incidence and channel (R, G, B in their colours; the incidence by the dash), as an SVG element.
std::string inplane_svg(const TabulatedBsdfTable& table,
                        const std::vector<double>& incidences_deg = {0, 30, 60, 75});

// Writes the page atomically. weft::Error when the viewer's scripts are missing under 'roots'
// (before the fit; nothing is written).
ExportReport write_preview_html(
    const TabulatedBsdfTable& table, const std::filesystem::path& path, const std::string& name,
    const GltfFitOptions& options = {},
    const std::vector<std::filesystem::path>& roots = bundled_data_roots());

}  // namespace weft
