// The suite's summary and page (suite.h): a row per fabric, read back from its metrics.json.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "common.h"
#include "weft/core/install_paths.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/verify/figures.h"
#include "weft/verify/models.h"
#include "weft/verify/suite.h"
#include "weft/verify/verdict.h"

namespace weft {
namespace {

namespace fs = std::filesystem;

// The models a suite row shows (the first three of kVerifyModels: no fitted ones).
struct SuiteModel {
  const char* key;     // metrics.json "models" key
  const char* prefix;  // of the headline keys
  const char* label;
};
constexpr SuiteModel suite_model(size_t k) {
  return {kVerifyModels[k].key, kVerifyModels[k].headline, kVerifyModels[k].short_label};
}
constexpr SuiteModel kSuiteModels[] = {suite_model(0), suite_model(1), suite_model(2)};

// The page's figures, in kFigureKeys order: their column heads and the model figure of each.
struct SuiteFigure {
  const char* key;     // kFigureKeys: the verdict's
  const char* head;    // the page's column
  const char* figure;  // model_figures' key
};
constexpr SuiteFigure kSuiteFigures[] = {{kFigureKeys[0], "shape", "shape_rms_log"},
                                         {kFigureKeys[1], "paper's", "paper_rms_log"},
                                         {kFigureKeys[2], "absolute", "absolute_rms_log"}};

// A figure's column head: the absolute figure of a calibrated suite is its calibrated one.
std::string figure_head(const SuiteFigure& figure, bool calibrated) {
  return calibrated && std::string(figure.key) == kFigureKeys[2] ? "calibrated" : figure.head;
}

// A number of a JSON object, or NaN when absent or not a number.
double number_at(const nlohmann::json& j, const nlohmann::json::json_pointer& p) {
  if (!j.contains(p)) return std::nan("");
  const nlohmann::json& v = j.at(p);
  return v.is_number() ? v.get<double>() : std::nan("");
}

nlohmann::json finite_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

// One model's figures in a fabric's metrics.json (docs/verify.md gives its keys): shape with its
// seed standard error, the spread over the measurement's fits and its error per channel, the
// paper's one-point and the absolute RMS log.
nlohmann::json model_figures(const nlohmann::json& m, const SuiteModel& model) {
  using P = nlohmann::json::json_pointer;
  const std::string base = std::string("/models/") + model.key;
  if (!m.contains(P(base))) return nullptr;
  const auto at = [&](const std::string& path) {
    return finite_or_null(number_at(m, P(base + path)));
  };
  return {{"shape_rms_log", at("/shape/rms_log")},
          {"shape_seed_se", at("/uncertainty/shape/seed_se")},
          {"shape_fit_min", at("/uncertainty/shape/fit_min")},
          {"shape_fit_max", at("/uncertainty/shape/fit_max")},
          {"shape_rms_log_channel",
           {{"R", at("/shape/rms_log_channel/R")},
            {"G", at("/shape/rms_log_channel/G")},
            {"B", at("/shape/rms_log_channel/B")}}},
          {"paper_rms_log", at("/normalized/rms_log")},
          {"absolute_rms_log", at("/absolute/rms_log")},
          {"calibrated_rms_log", at("/calibrated/rms_log")}};
}

// The report's verdicts on one figure ("shape", "paper_normalized", "absolute"): their texts.
std::vector<std::string> verdict_texts(const nlohmann::json& metrics, const std::string& figure) {
  std::vector<std::string> texts;
  const nlohmann::json::json_pointer p("/verdict/" + figure);
  if (!metrics.contains(p) || !metrics.at(p).is_array()) return texts;
  for (const auto& v : metrics.at(p))
    if (v.contains("text") && v.at("text").is_string()) texts.push_back(v.at("text"));
  return texts;
}

// The verdict of the computed ray trace against the classic model on one figure: "computed",
// "classic", "tie", "no_model" (no model describes the sample), "not_comparable" (a figure that
// includes the colour's level in another colour space) or "unresolved" (a figure not defined);
// empty when the report has no such verdict.
std::string figure_closer(const nlohmann::json& metrics, const std::string& figure) {
  const nlohmann::json::json_pointer p("/verdict/" + figure);
  if (!metrics.contains(p) || !metrics.at(p).is_array()) return "";
  const nlohmann::json::json_pointer none("/verdict/no_model_describes");
  if (metrics.contains(none) && metrics.at(none).is_boolean() && metrics.at(none).get<bool>())
    return "no_model";
  const std::string computed = verify_model_key(VerifyModel::kComputedRaytrace),
                    classic = verify_model_key(VerifyModel::kClassic);
  for (const auto& v : metrics.at(p)) {
    const std::string a = v.value("a", ""), b = v.value("b", "");
    const bool pair = (a == computed && b == classic) || (a == classic && b == computed);
    if (!pair) continue;
    if (!v.value("comparable", true)) return "not_comparable";
    if (!v.value("resolved", false)) return v.value("tie", false) ? "tie" : "unresolved";
    return v.value("closer", "") == classic ? "classic" : "computed";
  }
  return "";
}

// A path as the page shows it: relative to the suite file's folder, or, where that climbs out of
// it, to the bundled data's root it lies under (an install's share/weft, or the source tree), so
// that the page names no folder of this machine. A name that is no file (a preset) stays as is.
std::string suite_shown_path(const std::string& p, const fs::path& suite_dir) {
  if (p.empty()) return p;
  std::error_code ec;
  if (!fs::path(p).has_parent_path() && !fs::exists(p, ec)) return p;
  const auto full = [](const fs::path& q) {
    std::error_code e;
    const fs::path a = fs::absolute(q.empty() ? fs::path(".") : q, e);
    const fs::path c = fs::weakly_canonical(a, e);
    return e ? a.lexically_normal() : c;
  };
  const fs::path file = full(p);
  const auto inside = [&](const fs::path& root) {
    const fs::path rel = file.lexically_relative(full(root));
    return rel.empty() || *rel.begin() == ".." ? fs::path() : rel;
  };
  if (const fs::path rel = inside(suite_dir); !rel.empty()) return rel.generic_string();
  for (const fs::path& root : bundled_data_roots())
    if (const fs::path rel = inside(root); !rel.empty()) return rel.generic_string();
  const fs::path up = file.lexically_relative(full(suite_dir));
  return up.empty() ? fs::path(p).filename().generic_string() : up.generic_string();
}

// The fiber's dye recipe in words ("congo-red 2 % + curcumin 0.2 % owf"); empty where the fiber
// is no spec (a baked table) or can no longer be read.
std::string suite_fiber_dyes(const std::string& fiber) {
  try {
    const FiberSpec spec = load_fiber_spec(fiber);
    std::string out;
    for (const DyeComponent& d : spec.dyes)
      out += (out.empty() ? "" : " + ") + d.dye + " " + fmt(d.concentration_owf_percent) + " %";
    return out.empty() ? "no dye recipe" : out + " owf";
  } catch (const std::exception&) {
    return "";
  }
}

// A calibrated fabric's colour match, short: the dyes as matched ("congo-red 1.2 % + curcumin
// 0.3 % owf"), the distance reached and whether the target was out of the dyes' reach.
nlohmann::json suite_colour_match(const nlohmann::json& metrics) {
  const nlohmann::json& m = metrics.at("colour_match");
  std::string dyes;
  if (m.contains("dye_scale") && m.at("dye_scale").is_array())
    for (const auto& d : m.at("dye_scale"))
      if (d.contains("dye") && d.contains("scale") && d.at("scale").is_number())
        dyes += (dyes.empty() ? "" : " + ") + d.value("dye", std::string()) + " " +
                fmt(d.at("scale").get<double>(), 3) + " %";
  const bool recipe = m.value("basis", std::string()).rfind("the recipe", 0) == 0;
  return {{"dyes", dyes.empty() ? "" : dyes + (recipe ? " owf" : " (thread-colour absorbers)")},
          {"delta_e00", m.contains("delta_e00") ? m.at("delta_e00") : nlohmann::json()},
          {"outside_reach", m.value("outside_reach", false)}};
}

nlohmann::json suite_row_json(const SuiteRow& r, const fs::path& suite_dir) {
  nlohmann::json j = {{"name", r.fabric.name},
                      {"measured", r.fabric.measured},
                      {"fiber", r.fabric.fiber},
                      {"weave", r.fabric.weave},
                      {"pattern", r.fabric.pattern},
                      {"wif", r.fabric.wif},
                      {"colour_space", r.fabric.colour_space},
                      {"known", r.fabric.known},
                      {"report", r.fabric.name + "/index.html"}};
  // The paths as the page shows them (suite_shown_path), and the fiber's dyes.
  j["shown"] = {{"measured", suite_shown_path(r.fabric.measured, suite_dir)},
                {"fiber", suite_shown_path(r.fabric.fiber, suite_dir)},
                {"weave", suite_shown_path(r.fabric.weave, suite_dir)},
                {"wif", suite_shown_path(r.fabric.wif, suite_dir)}};
  j["dyes"] = suite_fiber_dyes(r.fabric.fiber);
  if (!r.error.empty()) {
    j["error"] = r.error;
    return j;
  }
  nlohmann::json models = nlohmann::json::object();
  for (const SuiteModel& model : kSuiteModels) {
    const nlohmann::json f = model_figures(r.metrics, model);
    if (!f.is_null()) models[model.key] = f;
  }
  j["models"] = models;
  j["absolute_comparable"] = r.metrics.value("absolute_comparable", true);
  j["shape_closer"] = figure_closer(r.metrics, "shape");
  nlohmann::json closer = nlohmann::json::object();
  for (const char* figure : kFigureKeys) closer[figure] = figure_closer(r.metrics, figure);
  j["closer"] = closer;
  j["shape_verdicts"] = verdict_texts(r.metrics, "shape");
  // A deep dye's spectrum can leave the sRGB gamut: its negative components are kept (none
  // clipped, unlike reports before) and the log figures floor them (figures.h).
  j["computed_gamut_clipped_components"] =
      r.metrics.value("fabric_table_gamut_clipped_components", 0);
  j["computed_out_of_gamut_components"] =
      r.metrics.value("fabric_table_out_of_gamut_components", 0);
  j["computed_log_floored_points"] = finite_or_null(number_at(
      r.metrics, nlohmann::json::json_pointer(std::string("/models/") +
                                              verify_model_key(VerifyModel::kComputedRaytrace) +
                                              "/log_floored_points")));
  j["no_model_describes"] = j["shape_closer"] == "no_model";
  j["colour_calibrated"] = r.metrics.value("colour_calibrated", false);
  if (r.metrics.contains("colour_match")) j["colour_match"] = suite_colour_match(r.metrics);
  if (r.metrics.contains("verdict")) j["verdict"] = r.metrics.at("verdict");
  return j;
}

nlohmann::json suite_rows_json(const VerifySuite& suite, const std::vector<SuiteRow>& rows) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& r : rows) list.push_back(suite_row_json(r, suite.file.parent_path()));
  return list;
}

std::string fixed_digits(const nlohmann::json& v, int digits) {
  if (!v.is_number()) return "&ndash;";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v.get<double>());
  return buf;
}
std::string fixed3(const nlohmann::json& v) {
  return fixed_digits(v, 3);
}

// How many fabrics' verdicts on one figure (computed ray trace vs classic) went each way.
nlohmann::json figure_counts(const nlohmann::json& rows, const std::string& figure) {
  int computed = 0, classic = 0, tie = 0, undefined = 0, no_model = 0, not_comparable = 0,
      not_run = 0;
  for (const auto& row : rows) {
    const nlohmann::json::json_pointer p("/closer/" + figure);
    const std::string c = row.contains(p) ? row.at(p).get<std::string>() : "";
    (c == "computed"         ? computed
     : c == "classic"        ? classic
     : c == "tie"            ? tie
     : c == "unresolved"     ? undefined
     : c == "no_model"       ? no_model
     : c == "not_comparable" ? not_comparable
                             : not_run)++;
  }
  // "unresolved" (kept for the readers of earlier pages) counts every verdict that names no
  // closer model: ties, undefined figures and samples no model describes.
  return {{"computed_closer", computed},
          {"classic_closer", classic},
          {"unresolved", tie + undefined + no_model},
          {"tie", tie},
          {"no_model_describes", no_model},
          {"not_comparable", not_comparable},
          {"without_verdict", not_run}};
}

// Whether the suite ran calibrated (--colour-from measured): its fabrics' reports say so.
bool suite_calibrated(const nlohmann::json& rows) {
  for (const auto& row : rows)
    if (row.value("colour_calibrated", false)) return true;
  return false;
}

std::string summary_sentence(const nlohmann::json& s) {
  const int undefined =
      s["unresolved"].get<int>() - s["tie"].get<int>() - s["no_model_describes"].get<int>();
  return "Shape, computed (ray trace) vs classic: computed closer on " +
         std::to_string(s["computed_closer"].get<int>()) + ", classic closer on " +
         std::to_string(s["classic_closer"].get<int>()) + ", a tie on " +
         std::to_string(s["tie"].get<int>()) + ", no model describes the sample on " +
         std::to_string(s["no_model_describes"].get<int>()) + " fabric(s)" +
         (undefined ? ", not defined on " + std::to_string(undefined) : "") +
         (s["without_verdict"].get<int>()
              ? ", " + std::to_string(s["without_verdict"].get<int>()) + " without a verdict"
              : "") +
         ".";
}

}  // namespace

std::string verify_suite_json(const VerifySuite& suite, const std::vector<SuiteRow>& rows) {
  nlohmann::json j;
  j["report"] = "weft verify suite";
  j["suite"] = suite.file.string();
  j["title"] = suite.title;
  j["figures"] =
      "per model: shape_rms_log (RMS of ln(model / measured) after one least-squares gain per "
      "channel, the same for every model; the headline; shape_rms_log_channel: per channel), "
      "paper_rms_log (the paper's one-point "
      "normalization at normal incidence and view), absolute_rms_log (no scaling: includes the "
      "colour level, comparable only where the colour spaces agree: absolute_comparable); "
      "shape_seed_se, the seed's standard error; shape_fit_min..shape_fit_max, the figure against "
      "each of the measurement's fits";
  const nlohmann::json list = suite_rows_json(suite, rows);
  // --colour-from measured: each fabric calibrated to its measurement's own d/8 reading, so the
  // absolute figure and its verdicts are the calibrated ones.
  j["colour_calibrated"] = suite_calibrated(list);
  j["fabrics"] = list;
  j["shape_summary"] = figure_counts(list, "shape");
  nlohmann::json per_figure = nlohmann::json::object();
  for (const char* figure : kFigureKeys) per_figure[figure] = figure_counts(list, figure);
  j["figure_summary"] = per_figure;
  return j.dump(2) + "\n";
}

std::string verify_suite_text(const std::vector<SuiteRow>& rows) {
  std::ostringstream out;
  char buf[256];
  nlohmann::json list = nlohmann::json::array();
  for (const auto& r : rows) list.push_back(suite_row_json(r, fs::path()));
  const bool calibrated = suite_calibrated(list);
  std::snprintf(buf, sizeof buf, "  %-28s %-30s %8s %8s %10s\n", "fabric", "model", "shape",
                "paper's", calibrated ? "calibrated" : "absolute");
  out << buf;
  for (size_t k = 0; k < rows.size(); ++k) {
    const SuiteRow& r = rows[k];
    const nlohmann::json& row = list[k];
    if (row.contains("error")) {
      out << "  " << r.fabric.name << ": failed: " << r.error << "\n";
      continue;
    }
    for (const SuiteModel& model : kSuiteModels) {
      if (!row["models"].contains(model.key)) continue;
      const nlohmann::json& f = row["models"][model.key];
      const auto num = [](const nlohmann::json& v) {
        return v.is_number() ? v.get<double>() : std::nan("");
      };
      std::snprintf(buf, sizeof buf, "  %-28s %-30s %8.3f %8.3f %10.3f\n", r.fabric.name.c_str(),
                    model.label, num(f["shape_rms_log"]), num(f["paper_rms_log"]),
                    num(f["absolute_rms_log"]));
      out << buf;
    }
    for (const auto& v : row["shape_verdicts"])
      out << "  " << r.fabric.name << ": " << v.get<std::string>() << "\n";
  }
  out << "  " << summary_sentence(figure_counts(list, "shape")) << "\n";
  if (calibrated) {
    const nlohmann::json c = figure_counts(list, kFigureKeys[2]);
    out << "  Calibrated (each fabric's colour from its measurement's d/8 reading), computed vs "
           "classic: computed closer on "
        << c["computed_closer"].get<int>() << ", classic closer on "
        << c["classic_closer"].get<int>() << ", a tie on " << c["tie"].get<int>() << ".\n";
  }
  return out.str();
}

namespace {

// The page is a scoreboard: one line per fabric at a fixed height, so that a screen of 1400 x 900
// holds the counts, the header and at least 20 rows; long text is cut with an ellipsis and given
// whole in a title (shown on hover) or in the details below the table.
constexpr const char* kSuitePageCss =
    "body{font:13px/1.3 sans-serif;margin:6px 12px}h1{font-size:17px;margin:0 0 4px}"
    "p.counts{margin:0 0 6px}p.counts span{padding:0 4px}table{border-collapse:collapse}"
    "td,th{border:1px solid #ccc;padding:1px 5px;line-height:1.3;white-space:nowrap;"
    "text-align:left}th{background:#f2f2f2;font-weight:600}"
    ".cut{display:inline-block;overflow:hidden;text-overflow:ellipsis;vertical-align:bottom}"
    "td.name .cut{max-width:14em}td.known .cut{max-width:28em}td.failed .cut{max-width:60em}"
    "td.v{text-align:center}td.ch{font-size:11px;text-align:right;color:#333}"
    "small{font-size:11px}.computed{background:#c3e6c3}.classic{background:#f2c4c4}"
    ".tie,.no_model,.unresolved,.not_comparable,.none{background:#e2e2e2}"
    "p.details{max-width:90em;color:#333}";

// A verdict's cell: its class (figure_closer's value, "none" without a verdict) and its word, so
// that the colour is never the only sign.
std::string suite_verdict_word(const std::string& closer) {
  return closer == "computed"         ? "computed"
         : closer == "classic"        ? "classic"
         : closer == "tie"            ? "tie"
         : closer == "no_model"       ? "no model"
         : closer == "unresolved"     ? "not defined"
         : closer == "not_comparable" ? "not comparable"
                                      : "&ndash;";
}

std::string joined(const std::vector<std::string>& texts, const std::string& separator) {
  std::string out;
  for (const auto& t : texts) out += (out.empty() ? "" : separator) + t;
  return out;
}

// Every model's value of a figure, for a title: the shape with the seed's standard error and the
// range against the measurement's fits.
std::string suite_figure_values(const nlohmann::json& row, const SuiteFigure& figure) {
  std::string out;
  for (const SuiteModel& model : kSuiteModels) {
    out += std::string(out.empty() ? "" : "; ") + model.label + " ";
    if (!row["models"].contains(model.key)) {
      out += "not run";
      continue;
    }
    const nlohmann::json& f = row["models"][model.key];
    out += fixed3(f[figure.figure]);
    if (std::string(figure.key) != "shape") continue;
    if (f["shape_seed_se"].is_number()) out += " &plusmn; " + fixed3(f["shape_seed_se"]);
    if (f["shape_fit_min"].is_number() && f["shape_fit_max"].is_number())
      out += " (fits " + fixed3(f["shape_fit_min"]) + "&ndash;" + fixed3(f["shape_fit_max"]) + ")";
  }
  return out;
}

// A figure's verdict cell: coloured by the closer model, its word, and the computed and classic
// figures (in brackets where the figure is not comparable); the verdict's text in the title.
std::string suite_verdict_cell(const nlohmann::json& row, const SuiteFigure& figure) {
  const std::string closer = row["closer"].value(figure.key, "");
  const auto value = [&](VerifyModel m) {
    const std::string key = verify_model_key(m);
    return row["models"].contains(key) ? fixed3(row["models"][key][figure.figure])
                                       : std::string("&ndash;");
  };
  std::string values = value(VerifyModel::kComputedRaytrace) + " / " + value(VerifyModel::kClassic);
  if (closer == "not_comparable") values = "(" + values + ")";
  const std::string texts = joined(verdict_texts(row, figure.key), " ");
  return "<td class=\"v " + (closer.empty() ? std::string("none") : closer) + "\" title=\"" +
         html_escape(texts) + (texts.empty() ? "" : " ") +
         "Figures: " + suite_figure_values(row, figure) + "\">" + suite_verdict_word(closer) +
         " <small>" + values + "</small></td>";
}

// The computed and the classic model's shape error per channel, R G B each.
std::string suite_channel_cells(const nlohmann::json& row) {
  std::string out;
  for (VerifyModel m : {VerifyModel::kComputedRaytrace, VerifyModel::kClassic}) {
    const std::string key = verify_model_key(m);
    for (const char* channel : {"R", "G", "B"}) {
      const nlohmann::json::json_pointer p("/models/" + key + "/shape_rms_log_channel/" + channel);
      out += "<td class=\"ch\">" + fixed3(row.contains(p) ? row.at(p) : nlohmann::json()) + "</td>";
    }
  }
  return out;
}

// What is known, short (fiber, dyes, pattern, weave), with the source's words, the measured
// file, the colour space and the computed table's gamut in the title.
std::string suite_known_cell(const nlohmann::json& row) {
  const nlohmann::json& shown = row["shown"];
  std::string brief = "fiber " + html_escape(shown["fiber"].get<std::string>());
  if (row.contains("colour_match") && !row["colour_match"]["dyes"].get<std::string>().empty()) {
    const nlohmann::json& m = row["colour_match"];
    brief += " &middot; matched " + html_escape(m["dyes"].get<std::string>());
    if (m["delta_e00"].is_number())
      brief += " (&Delta;E00 " + fmt(m["delta_e00"].get<double>(), 3) +
               (m["outside_reach"].get<bool>() ? ", out of reach)" : ")");
  } else if (!row["dyes"].get<std::string>().empty()) {
    brief += " &middot; " + html_escape(row["dyes"].get<std::string>());
  }
  if (!row["pattern"].get<std::string>().empty())
    brief += " &middot; pattern " + html_escape(row["pattern"].get<std::string>());
  // The files last: the weave is the same few for many fabrics, so the ellipsis may take it.
  if (!shown["wif"].get<std::string>().empty())
    brief += " &middot; wif " + html_escape(shown["wif"].get<std::string>());
  if (!shown["weave"].get<std::string>().empty())
    brief += " &middot; weave " + html_escape(shown["weave"].get<std::string>());
  const std::string space = row["colour_space"].get<std::string>();
  std::string title = row["known"].get<std::string>() +
                      " Measured: " + shown["measured"].get<std::string>() + ", colour space " +
                      (space.empty() ? "as the file says" : space) + ".";
  if (!row.contains("error")) {
    title +=
        " Computed table: " + std::to_string(row.value("computed_gamut_clipped_components", 0)) +
        " components clipped, " + std::to_string(row.value("computed_out_of_gamut_components", 0)) +
        " outside the sRGB gamut (kept)";
    if (row["computed_log_floored_points"].is_number())
      title += ", " + fmt(row["computed_log_floored_points"].get<double>(), 9) + " points floored";
    title += ".";
  }
  return "<td class=\"known\" title=\"" + html_escape(title) + "\"><span class=\"cut\">" + brief +
         "</span></td>";
}

std::string suite_html_row(const nlohmann::json& row) {
  const std::string name = html_escape(row["name"].get<std::string>());
  std::string h = "<tr><td class=\"name\"><span class=\"cut\"><a href=\"" + name +
                  "/index.html\">" + name + "</a></span></td>" + suite_known_cell(row);
  if (row.contains("error")) {
    const std::string error = html_escape(row["error"].get<std::string>());
    return h + "<td class=\"failed none\" colspan=\"9\" title=\"" + error +
           "\"><span class=\"cut\">failed: " + error + "</span></td></tr>\n";
  }
  for (const SuiteFigure& figure : kSuiteFigures) h += suite_verdict_cell(row, figure);
  return h + suite_channel_cells(row) + "</tr>\n";
}

// One line per figure: on how many fabrics each model is closer, ties, and the rest.
std::string suite_counts(const nlohmann::json& rows) {
  const bool calibrated = suite_calibrated(rows);
  std::string h =
      "<p class=\"counts\" id=\"counts\">Fabrics on which the computed model (ray trace) or the "
      "classic model is closer to the measurement, beyond the uncertainty:";
  for (const SuiteFigure& figure : kSuiteFigures) {
    const nlohmann::json c = figure_counts(rows, figure.key);
    const auto count = [&](const char* key) { return std::to_string(c[key].get<int>()); };
    const int undefined =
        c["unresolved"].get<int>() - c["tie"].get<int>() - c["no_model_describes"].get<int>();
    h += "<br><b>" + figure_head(figure, calibrated) + "</b>: <span class=\"computed\">computed " +
         count("computed_closer") + "</span> <span class=\"classic\">classic " +
         count("classic_closer") + "</span> <span class=\"tie\">tie " + count("tie") +
         "</span> <span class=\"no_model\">no model describes " + count("no_model_describes") +
         "</span>";
    if (undefined)
      h += " <span class=\"unresolved\">not defined " + std::to_string(undefined) + "</span>";
    if (c["not_comparable"].get<int>())
      h += " <span class=\"not_comparable\">not comparable " + count("not_comparable") + "</span>";
    if (c["without_verdict"].get<int>())
      h += " <span class=\"none\">without a verdict " + count("without_verdict") + "</span>";
  }
  return h + "</p>\n";
}

std::string suite_table_head(bool calibrated) {
  std::string h =
      "<table>\n<thead><tr><th rowspan=\"2\">fabric</th><th rowspan=\"2\">what is known</th>"
      "<th colspan=\"3\">closer: computed (ray trace) / classic figures</th>"
      "<th colspan=\"3\">computed shape R G B</th><th colspan=\"3\">classic shape R G B</th>"
      "</tr>\n<tr>";
  for (const SuiteFigure& figure : kSuiteFigures)
    h += "<th>" + figure_head(figure, calibrated) + "</th>";
  for (int k = 0; k < 2; ++k) h += "<th>R</th><th>G</th><th>B</th>";
  return h + "</tr></thead>\n<tbody>\n";
}

// What the figures are and how a verdict is reached, below the table.
std::string suite_details(bool calibrated) {
  const std::string level =
      calibrated
          ? "<b>calibrated</b> (the suite ran with --colour-from measured: each fabric's dyes "
            "were scaled so that the cloth's d/8 reading meets its own measurement's, and every "
            "unfitted model is made of that fiber; then no scaling at all: the absolute figure "
            "after that one calibration, judged in every colour space, since the colour came "
            "from the measurement itself; the matched recipe and its &Delta;E00 are in the "
            "second column)"
          : "<b>absolute</b> (includes the colour level: comparable only where model and "
            "measurement share a colour space; in brackets and &ldquo;not comparable&rdquo; "
            "otherwise)";
  return "<p class=\"details\">Each fabric is verified with what is known of its sample "
         "(construction, fiber, colour space), never with its measured curve; hover a cell for "
         "the source's words and every model's figures. Figures are RMS of ln(model / measured) "
         "over views up to 80&deg;: <b>shape</b> after one least-squares gain per channel, the "
         "same procedure for every model (the headline; per channel R G B in the last columns); "
         "<b>paper's</b> one-point normalization (Voloboy et al. 2010: hinges on the "
         "normal-incidence, normal-view point); " +
         level +
         ". Linear sRGB is not clipped: a channel outside "
         "the gamut is kept, and the logs floor each channel at " +
         fmt(kLogFloorFraction) +
         " of its own maximum. A verdict names a closer model (green: the computed model, red: "
         "the classic one) only when the difference exceeds " +
         fmt(kVerdictSeedErrors) +
         " seed standard errors and the measurement's own spread between its fits (with one fit, "
         "spread unknown: the smallest such spread on the bundled MERL measurements); otherwise "
         "it is a tie (grey). Where every model's shape is above " +
         fmt(kNoModelShapeRmsLog) + ", no model here describes the sample (grey).</p>\n";
}

}  // namespace

std::string verify_suite_html(const VerifySuite& suite, const std::vector<SuiteRow>& rows) {
  const nlohmann::json list = suite_rows_json(suite, rows);
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>weft verify suite: "
    << html_escape(suite.title) << "</title>\n<style>" << kSuitePageCss
    << "</style></head><body>\n<h1>" << html_escape(suite.title) << "</h1>\n"
    << suite_counts(list) << suite_table_head(suite_calibrated(list));
  for (const auto& row : list) h << suite_html_row(row);
  h << "</tbody></table>\n" << suite_details(suite_calibrated(list)) << "</body></html>\n";
  return h.str();
}

}  // namespace weft
