#include "weft/verify/report.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <system_error>
#include <tuple>

#include "common.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/exchange/preview_html.h"

namespace weft {
namespace {

// The plots draw() wrote into 'folder', to embed (file name -> bytes, by name): every PNG but the
// renders, which the page links beside their EXR (relative paths).
std::vector<std::pair<std::string, std::string>> embedded_plots(
    const std::filesystem::path& folder) {
  namespace fs = std::filesystem;
  std::vector<std::pair<std::string, std::string>> images;
  std::vector<fs::path> pngs;
  for (const auto& e : fs::directory_iterator(folder))
    if (e.path().extension() == ".png" && e.path().filename().string().rfind("render-", 0) != 0)
      pngs.push_back(e.path());
  std::sort(pngs.begin(), pngs.end());
  for (const auto& p : pngs) {
    std::ifstream f(p, std::ios::binary);
    std::ostringstream b;
    b << f.rdbuf();
    images.emplace_back(p.filename().string(), b.str());
  }
  return images;
}

}  // namespace

std::string verify_inplane_csv(const VerifyReport& r) {
  std::ostringstream o;
  o.precision(9);
  o << "theta_i_deg,view_zenith_deg,model,channel,beta,beta_err,beta_norm,norm_factor\n";
  const char* ch[3] = {"R", "G", "B"};
  for (size_t i = 0; i < r.measured.curves.size(); ++i) {
    const auto& c = r.measured.curves[i];
    for (size_t v = 0; v < c.view_deg.size(); ++v) {
      for (int k = 0; k < 3; ++k)
        o << c.theta_i_deg << ',' << c.view_deg[v] << ",measured," << ch[k] << ',' << c.beta[v][k]
          << ",0," << c.beta[v][k] << ",1\n";
      for (const auto& m : r.models)
        for (int k = 0; k < 3; ++k) {
          const double f = m.normalization[k];
          o << c.theta_i_deg << ',' << c.view_deg[v] << ',' << m.key << ',' << ch[k] << ','
            << m.beta[i][v][k] << ',' << m.beta_err[i][v][k] << ',' << m.beta[i][v][k] * f << ','
            << f << '\n';
        }
    }
  }
  return o.str();
}

std::vector<VerifyPreview> write_verify_previews(const std::filesystem::path& folder,
                                                 const VerifyReport& report, std::string* skipped) {
  std::vector<VerifyPreview> out;
  if (!report.computed_fabric && !report.classic_fabric) return out;
  try {
    load_viewer_modules();
  } catch (const Error& e) {
    *skipped = e.what();
    return out;
  }
  for (const auto& [table, model, label] :
       {std::tuple{&report.computed_fabric, "computed", "computed fabric (fiber-level ray trace)"},
        std::tuple{&report.classic_fabric, "classic", "classic fiber (Lambert + Cook-Torrance)"}}) {
    if (!*table) continue;
    VerifyPreview p{model, std::string("preview-") + model + ".html", label};
    // The page is a cloth's, whatever kind the table was made with.
    TabulatedBsdfTable fabric = **table;
    fabric.kind = "fabric";
    write_preview_html(fabric, folder / p.file, std::string(model) + ": " + label);
    out.push_back(std::move(p));
  }
  return out;
}

void check_verify_output(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path target = fs::absolute(dir);
  const fs::path parent = target.parent_path();
  if (!fs::is_directory(parent, ec))
    throw Error(dir.string(), "-o", "the output's parent directory does not exist");
  if (fs::exists(target, ec)) {
    if (!fs::is_directory(target, ec))
      throw Error(dir.string(), "-o", "exists and is not a directory");
    if (!fs::is_empty(target, ec)) {
      std::ifstream m(target / "metrics.json");
      nlohmann::json j = nlohmann::json::parse(m, nullptr, false);
      if (j.is_discarded() || !j.is_object() || j.value("report", "") != "weft verify")
        throw Error(dir.string(), "-o",
                    "exists and holds something other than an earlier weft verify report; "
                    "refusing to replace it");
    }
  }
}

bool write_verify_report(const std::filesystem::path& dir, const VerifyReport& report,
                         const std::function<void(const std::filesystem::path&)>& draw,
                         const ProgressCallback& progress) {
  namespace fs = std::filesystem;
  check_verify_output(dir);
  std::error_code ec;
  const fs::path target = fs::absolute(dir);
  // A staging folder named as atomic_file.h names temporaries, so that one a killed run left is
  // removed by the next; the earlier report moved aside is never removed that way.
  const fs::path staging = temporary_sibling(target);
  const fs::path old = fs::path(staging.string() + "-old");
  try {
    if (!fs::create_directory(staging, ec) || ec)
      throw Error(dir.string(), "-o", "cannot create a staging folder beside it");
    // The renders first, so that metrics.json and index.html describe them and their time.
    VerifyReport r = report;
    const auto t0 = std::chrono::steady_clock::now();
    // Stopped: the staging folder goes, and with it whatever was written. Asked after the
    // renders, the previews and the plots (draw() ends its script early on the front end's own
    // poll), so that a stop between steps does not wait for the next.
    bool cancelled = false;
    const auto stopped = [&](uint64_t step) {
      cancelled = cancelled || !progress({"report", step, 3, "steps"});
      if (cancelled) fs::remove_all(staging, ec);
      return cancelled;
    };
    r.renders = render_verify_samples(staging, r, progress, &cancelled);
    if (stopped(1)) return false;
    for (const auto& v : r.renders) {
      write_exr(staging / (v.stem + ".exr"), v.image);
      write_png_preview(staging / (v.stem + ".png"), v.image, kVerifyRenderExposure);
    }
    r.seconds["renders"] = seconds_since(t0);
    const auto t1 = std::chrono::steady_clock::now();
    r.previews = write_verify_previews(staging, r, &r.previews_skipped);
    r.seconds["previews"] = seconds_since(t1);
    if (stopped(2)) return false;
    write_text_atomically(staging / "inplane.csv", verify_inplane_csv(r));
    write_text_atomically(staging / "metrics.json", verify_metrics_json(r));
    draw(staging);
    if (stopped(3)) return false;
    write_text_atomically(staging / "index.html", verify_index_html(r, embedded_plots(staging)));
    // The earlier report (if any) is moved aside, the new one moved in, the old one removed.
    if (fs::exists(target, ec)) {
      fs::rename(target, old, ec);
      if (ec) throw Error(dir.string(), "-o", "cannot move the earlier report aside");
    }
    fs::rename(staging, target, ec);
    if (ec) throw Error(dir.string(), "-o", "cannot move the finished report into place");
  } catch (...) {
    fs::remove_all(staging, ec);
    if (fs::exists(old, ec) && !fs::exists(target, ec)) fs::rename(old, target, ec);
    throw;
  }
  fs::remove_all(old, ec);
  return true;
}

}  // namespace weft
