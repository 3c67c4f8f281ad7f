#pragma once
// weft export -o X.html and weft view: one self-contained page that previews the glTF material
// fitted to a table (gltf_material.h) on a cushion and a cloth draped over a sphere, lit by an
// environment and orbitable with the mouse, beside the table's own in-plane curves (the incidence
// chosen on the page) and the fit's figures. The page fetches nothing: the .glb (the one weft
// export -o X.glb writes, with the preview's two meshes instead of the sample quad) is in it as
// base64, the viewer is three.js (pinned in exchange/viewer/package-lock.json, installed by
// scripts/install-viewer.sh) inlined as data: URL modules under an import map, and the curves are
// an inline SVG drawn here.
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
// The in-plane plot's control (exchange/viewer/inplane.js), which every page holds, with or
// without three.js; weft::Error naming the file when it is missing.
std::string load_inplane_script(
    const std::vector<std::filesystem::path>& roots = bundled_data_roots());

// The incidences the page's plot offers, one shown at a time: 0, 5, ..., 85 degrees.
std::vector<double> preview_incidences_deg();

// The in-plane radiance coefficient beta = pi f of the table (materials/table_inplane.h) at each
// incidence of 'incidences_deg', views -90..90 degrees (> 0 on the mirror side), one line per
// channel (R, G, B in their colours) on one scale for all incidences, as an SVG element. Each
// incidence is a group <g class='weft-incidence' data-incidence='DEG'>; only the one nearest
// 'shown_deg' is displayed, and the page's control (exchange/viewer/inplane.js) switches them.
std::string inplane_svg(const TabulatedBsdfTable& table,
                        const std::vector<double>& incidences_deg = preview_incidences_deg(),
                        double shown_deg = 0);

// What the page shows beside the table's curves.
struct PreviewPage {
  // The glTF material fitted to the table, in 3-D on the cushion and the drape (three.js). Without
  // it the page holds the curves alone and needs no three.js: weft view's page of a fiber table,
  // whose directions are a fiber's, not a cloth's (view_request.h).
  bool material = true;
  std::vector<double> incidences_deg = preview_incidences_deg();  // each in [0, 90)
  std::vector<std::string> notes;  // added to the report and, without the material, to the page
};

// Writes the page atomically. weft::Error when the viewer's scripts are missing under 'roots'
// (before the fit; nothing is written).
ExportReport write_preview_html(
    const TabulatedBsdfTable& table, const std::filesystem::path& path, const std::string& name,
    const GltfFitOptions& options = {},
    const std::vector<std::filesystem::path>& roots = bundled_data_roots(),
    const PreviewPage& shows = {});

}  // namespace weft
