// weft export -o X.html: the page (preview_html.h). Everything it shows is inside it, so that it
// opens offline, from a mail or an archive, years later.
#include "weft/exchange/preview_html.h"

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "gltf_asset.h"
#include "preview_geometry.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/hash.h"
#include "weft/core/html.h"
#include "weft/core/install_paths.h"

namespace weft {
namespace {

const std::filesystem::path kViewerDir = "exchange/viewer";
const std::filesystem::path kThreeDir = kViewerDir / "node_modules/three";

// The modules the page imports, by the name it imports them and their file in the three package.
struct ModuleFile {
  const char* specifier;
  const char* file;
};
constexpr ModuleFile kModuleFiles[] = {
    {"three", "build/three.module.min.js"},
    {"weft/GLTFLoader", "examples/jsm/loaders/GLTFLoader.js"},
    {"weft/BufferGeometryUtils", "examples/jsm/utils/BufferGeometryUtils.js"},
    {"weft/OrbitControls", "examples/jsm/controls/OrbitControls.js"},
    {"weft/RoomEnvironment", "examples/jsm/environments/RoomEnvironment.js"},
};

std::string read_viewer_file(const std::vector<std::filesystem::path>& roots,
                             const std::filesystem::path& rel) {
  std::string tried;
  const auto path = find_file_under(roots, rel, &tried);
  if (path.empty())
    throw Error(rel.string(), "",
                "missing: the HTML preview inlines three.js from exchange/viewer; run "
                "scripts/install-viewer.sh (it installs the version pinned in "
                "exchange/viewer/package-lock.json; needs npm once). Looked in: " +
                    tried);
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw Error(path.string(), "", "cannot be read");
  return text.str();
}

// A module under a data: URL has no folder to resolve a relative import against, so the one
// relative import of the pinned version (GLTFLoader's BufferGeometryUtils) is renamed to a name
// the import map holds. A version that no longer has it is refused, not shipped broken.
void rename_relative_import(std::string& source, const std::string& from, const std::string& to,
                            const std::string& file) {
  const std::string quoted = "'" + from + "'";
  const size_t at = source.find(quoted);
  if (at == std::string::npos)
    throw Error(file, "",
                "does not import " + quoted +
                    " as the pinned three.js does: "
                    "install the pinned version (scripts/install-viewer.sh)");
  source.replace(at, quoted.size(), "'" + to + "'");
}

std::string three_version(const std::vector<std::filesystem::path>& roots) {
  const auto j = nlohmann::json::parse(read_viewer_file(roots, kThreeDir / "package.json"));
  return j.value("version", std::string("?"));
}

std::string bytes_base64(const std::string& bytes) {
  return base64({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()});
}

// The page's import map: every module as a base64 data: URL, which the browser loads without
// any fetch.
std::string import_map(const std::vector<ViewerModule>& modules) {
  nlohmann::json imports = nlohmann::json::object();
  for (const auto& m : modules)
    if (!m.specifier.empty())
      imports[m.specifier] = "data:text/javascript;base64," + bytes_base64(m.source);
  return nlohmann::json{{"imports", imports}}.dump();
}

std::string fit_section(const ExportReport& r) {
  std::ostringstream h;
  h << "<section id='weft-fit'><h2>The fit</h2>\n<table>\n";
  for (const auto& [name, value] : r.figures)
    h << "<tr><td>" << html_escape(name) << "</td><td>" << value << "</td></tr>\n";
  h << "</table>\n<h3>What the glTF material drops</h3>\n<ul>\n";
  for (const auto& d : r.dropped) h << "<li>" << html_escape(d) << "</li>\n";
  h << "</ul>\n<h3>Notes</h3>\n<ul>\n";
  for (const auto& n : r.notes) h << "<li>" << html_escape(n) << "</li>\n";
  h << "</ul>\n</section>\n";
  return h.str();
}

constexpr const char* kStyle = R"(<style>
body { font-family: sans-serif; margin: 1em 2em; color: #222; }
.weft-row { display: flex; flex-wrap: wrap; gap: 1.5em; align-items: flex-start; }
#weft-view { width: 640px; height: 480px; border: 1px solid #999; }
figure { margin: 0; max-width: 520px; }
td { padding: 0.1em 0.8em 0.1em 0; }
</style>
)";

// A script inlined in a <script> element, which the first "</script" in it would end.
void check_inlinable(const std::string& source, const std::filesystem::path& file) {
  if (source.find("</script") != std::string::npos)
    throw Error(file.string(), "", "holds '</script', which ends the page's script");
}

// The part of the page that shows the table's curves and the control choosing their incidence.
std::string curves_figure(const TabulatedBsdfTable& table, const PreviewPage& p) {
  std::ostringstream h;
  const auto& inc = p.incidences_deg;
  h << "<figure>" << inplane_svg(table, inc, inc.front())
    << "<p><label for='weft-incidence'>Light at &#952;i = <output id='weft-incidence-value'>"
    << inc.front() << "&#176;</output></label><br><input type='range' id='weft-incidence' min='0' "
    << "max='" << inc.size() - 1 << "' step='1' value='0' style='width: 380px'></p>\n"
    << "<figcaption>The table's in-plane curves";
  if (p.material) h << " (not the fit's)";
  h << ": &#946; = &#960; f per channel (R, G, B), light at &#952;i (" << inc.front()
    << "&#176; to " << inc.back() << "&#176;, chosen above), averaged over the azimuth";
  if (table.kind == "fiber")
    h << "; in the frame of a point on the fiber (z its outward normal, x the fiber's axis), as "
         "the "
         "fiber table stores it";
  h << ".</figcaption></figure>\n";
  return h.str();
}

// The preview's .glb: the fitted material on the cushion and the drape, placed side by side.
std::string preview_glb(const GltfFit& fit, const std::string& name, double epsilon_per_sr,
                        const std::string& path) {
  using namespace gltf_detail;
  GltfMesh cushion = cushion_mesh();
  cushion.translation_m[0] = -0.8;
  GltfMesh drape = drape_mesh();
  drape.translation_m = {0.35, 0, -0.1};
  return gltf_asset(fit, name, epsilon_per_sr, {cushion, drape}, true, path);
}

struct PageParts {
  std::string name, svg_figure, inplane_js;
  // With the material: three.js and preview.js, the .glb, the fit's report, three's version.
  std::vector<ViewerModule> modules;
  std::string glb, three;
  ExportReport report;
};

std::string page(const PageParts& p, bool material) {
  std::ostringstream h;
  h << "<!doctype html>\n<html lang='en'>\n<head>\n<meta charset='utf-8'>\n<title>Weft preview: "
    << html_escape(p.name) << "</title>\n"
    << kStyle;
  if (material) h << "<script type='importmap'>" << import_map(p.modules) << "</script>\n";
  h << "</head>\n<body>\n";
  if (material) {
    h << "<h1>" << html_escape(p.name) << ": the glTF material fitted to the table</h1>\n"
      << "<div class='weft-row'>\n<div><div id='weft-view'></div>\n"
      << "<p id='weft-status'>Loading the preview (it needs JavaScript and WebGL).</p></div>\n"
      << p.svg_figure << "</div>\n"
      << fit_section(p.report)
      << "<p>The material (KHR_materials_sheen; three.js shows no "
         "KHR_materials_diffuse_transmission, "
      << "so a translucent cloth is shown opaque) on a cushion and a cloth draped over a sphere, "
      << "lit by three.js's RoomEnvironment. Viewer: three.js " << html_escape(p.three)
      << " (MIT licence, &#169; three.js authors), inlined.</p>\n"
      << "<script type='application/octet-stream' id='weft-glb'>" << bytes_base64(p.glb)
      << "</script>\n";
  } else {
    h << "<h1>" << html_escape(p.name) << ": the table's in-plane curves</h1>\n"
      << "<div class='weft-row'>\n"
      << p.svg_figure << "</div>\n<ul>\n";
    for (const auto& n : p.report.notes) h << "<li>" << html_escape(n) << "</li>\n";
    h << "</ul>\n";
  }
  // A classic script, so that the curves switch even where modules or WebGL fail.
  h << "<script>\n" << p.inplane_js << "</script>\n";
  if (material) {
    h << "<script type='module'>\n";
    for (const auto& m : p.modules)
      if (m.specifier.empty()) h << m.source;
    h << "</script>\n";
  }
  h << "</body>\n</html>\n";
  return h.str();
}

}  // namespace

std::vector<ViewerModule> load_viewer_modules(const std::vector<std::filesystem::path>& roots) {
  std::vector<ViewerModule> modules;
  for (const auto& f : kModuleFiles) {
    ViewerModule m{f.specifier, read_viewer_file(roots, kThreeDir / f.file)};
    if (m.specifier == "weft/GLTFLoader")
      rename_relative_import(m.source, "../utils/BufferGeometryUtils.js",
                             "weft/BufferGeometryUtils", f.file);
    modules.push_back(std::move(m));
  }
  ViewerModule own{"", read_viewer_file(roots, kViewerDir / "preview.js")};
  check_inlinable(own.source, kViewerDir / "preview.js");
  modules.push_back(std::move(own));
  return modules;
}

std::string load_inplane_script(const std::vector<std::filesystem::path>& roots) {
  const auto file = kViewerDir / "inplane.js";
  std::string source = read_viewer_file(roots, file);
  check_inlinable(source, file);
  return source;
}

ExportReport write_preview_html(const TabulatedBsdfTable& table, const std::filesystem::path& path,
                                const std::string& name, const GltfFitOptions& options,
                                const std::vector<std::filesystem::path>& roots,
                                const PreviewPage& shows) {
  using namespace gltf_detail;
  if (path.extension() != ".html")
    throw Error(path.string(), "output", "a preview page ends in .html");
  if (shows.incidences_deg.empty())
    throw Error(path.string(), "incidences", "the page needs at least one incidence");
  for (double t : shows.incidences_deg)
    if (!(t >= 0 && t < 90))
      throw Error(path.string(), "incidences", "an incidence lies in [0, 90) degrees");
  PageParts parts;
  parts.name = name;
  // Before the fit: a missing viewer fails at once.
  if (shows.material) {
    parts.modules = load_viewer_modules(roots);
    parts.three = three_version(roots);
  }
  parts.inplane_js = load_inplane_script(roots);
  if (shows.material) {
    const GltfFit fit = fit_gltf_material(table, options);
    parts.glb = preview_glb(fit, name, options.epsilon_per_sr, path.string());
    parts.report = gltf_report(fit);
    parts.report.format = "HTML preview of the glTF 2.0 material";
    parts.report.notes.push_back(
        "the page inlines the .glb (a cushion and a draped cloth), three.js " + parts.three +
        " (MIT) and the table's in-plane curves; it fetches nothing");
  } else {
    parts.report.format = "HTML page of the table's in-plane curves";
    parts.report.notes.push_back(
        "the page holds the table's in-plane curves at " +
        std::to_string(shows.incidences_deg.size()) +
        " incidences, one shown at a time, and no 3-D view; it fetches nothing");
  }
  for (const auto& n : shows.notes) parts.report.notes.push_back(n);
  parts.svg_figure = curves_figure(table, shows);
  write_text_atomically(path, page(parts, shows.material));
  return parts.report;
}

}  // namespace weft
