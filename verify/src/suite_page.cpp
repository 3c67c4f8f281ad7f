// The suite's summary and page (suite.h): a row per fabric, read back from its metrics.json.
#include <cmath>
#include <cstdio>
#include <sstream>

#include "weft/verify/suite.h"

namespace weft {
namespace {

// The models a suite row shows, with the prefix of their headline keys in metrics.json.
struct SuiteModel {
  const char* key;     // metrics.json "models" key
  const char* prefix;  // of the headline keys
  const char* label;
};
constexpr SuiteModel kSuiteModels[] = {
    {"computed_raytrace", "computed", "computed (ray trace)"},
    {"computed_summation", "summation", "computed (paper's summation)"},
    {"classic", "classic", "classic (Lambert + Cook-Torrance)"},
};

// A number of a JSON object, or NaN when absent or not a number.
double number_at(const nlohmann::json& j, const nlohmann::json::json_pointer& p) {
  if (!j.contains(p)) return std::nan("");
  const nlohmann::json& v = j.at(p);
  return v.is_number() ? v.get<double>() : std::nan("");
}

nlohmann::json finite_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

// One model's figures in a fabric's metrics.json: shape, the paper's one-point and absolute
// RMS log, with their uncertainties where the report gives them.
nlohmann::json model_figures(const nlohmann::json& m, const SuiteModel& model) {
  using P = nlohmann::json::json_pointer;
  const std::string base = std::string("/models/") + model.key;
  if (!m.contains(P(base))) return nullptr;
  nlohmann::json f;
  f["shape_rms_log"] = finite_or_null(number_at(m, P(base + "/shape/rms_log")));
  f["shape_seed_sd"] = finite_or_null(number_at(m, P(base + "/shape/seed_sd")));
  f["shape_measurement_spread"] =
      finite_or_null(number_at(m, P(base + "/shape/measurement_spread")));
  f["paper_rms_log"] = finite_or_null(number_at(m, P(base + "/normalized/rms_log")));
  f["absolute_rms_log"] = finite_or_null(number_at(m, P(base + "/absolute/rms_log")));
  return f;
}

nlohmann::json suite_row_json(const SuiteRow& r) {
  nlohmann::json j = {{"name", r.fabric.name},
                      {"measured", r.fabric.measured},
                      {"fiber", r.fabric.fiber},
                      {"weave", r.fabric.weave},
                      {"pattern", r.fabric.pattern},
                      {"wif", r.fabric.wif},
                      {"colour_space", r.fabric.colour_space},
                      {"known", r.fabric.known},
                      {"report", r.fabric.name + "/index.html"}};
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
  if (r.metrics.contains("verdict")) j["verdict"] = r.metrics.at("verdict");
  return j;
}

std::string html_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

std::string fixed3(const nlohmann::json& v) {
  if (!v.is_number()) return "&ndash;";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v.get<double>());
  return buf;
}

// A model's cell: shape +- seed (measurement spread), then the paper's and the absolute figure.
std::string model_cell(const nlohmann::json& f) {
  if (f.is_null()) return "<td colspan=\"3\">not run</td>";
  std::string shape = fixed3(f["shape_rms_log"]);
  if (f["shape_seed_sd"].is_number()) shape += " &plusmn; " + fixed3(f["shape_seed_sd"]);
  if (f["shape_measurement_spread"].is_number())
    shape += " <small>(fits " + fixed3(f["shape_measurement_spread"]) + ")</small>";
  return "<td>" + shape + "</td><td>" + fixed3(f["paper_rms_log"]) + "</td><td>" +
         fixed3(f["absolute_rms_log"]) + "</td>";
}

std::string verdict_text(const nlohmann::json& row) {
  if (!row.contains("verdict")) return "";
  const nlohmann::json& v = row.at("verdict");
  if (v.is_string()) return v.get<std::string>();
  if (v.is_object() && v.contains("text") && v.at("text").is_string())
    return v.at("text").get<std::string>();
  return v.dump();
}

}  // namespace

std::string verify_suite_json(const VerifySuite& suite, const std::vector<SuiteRow>& rows) {
  nlohmann::json j;
  j["report"] = "weft verify suite";
  j["suite"] = suite.file.string();
  j["title"] = suite.title;
  j["figures"] =
      "per model: shape_rms_log (RMS of ln(model / measured) after one least-squares gain per "
      "channel, the same for every model; the headline), paper_rms_log (the paper's one-point "
      "normalization at normal incidence and view), absolute_rms_log (no scaling: includes the "
      "colour level, comparable only where the colour spaces agree)";
  nlohmann::json list = nlohmann::json::array();
  for (const auto& r : rows) list.push_back(suite_row_json(r));
  j["fabrics"] = list;
  return j.dump(2) + "\n";
}

std::string verify_suite_text(const std::vector<SuiteRow>& rows) {
  std::ostringstream out;
  char buf[256];
  std::snprintf(buf, sizeof buf, "  %-28s %-30s %8s %8s %8s\n", "fabric", "model", "shape",
                "paper's", "absolute");
  out << buf;
  for (const auto& r : rows) {
    const nlohmann::json row = suite_row_json(r);
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
      std::snprintf(buf, sizeof buf, "  %-28s %-30s %8.3f %8.3f %8.3f\n", r.fabric.name.c_str(),
                    model.label, num(f["shape_rms_log"]), num(f["paper_rms_log"]),
                    num(f["absolute_rms_log"]));
      out << buf;
    }
    const std::string v = verdict_text(row);
    if (!v.empty()) out << "  " << r.fabric.name << ": " << v << "\n";
  }
  return out.str();
}

std::string verify_suite_html(const VerifySuite& suite, const std::vector<SuiteRow>& rows) {
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>weft verify suite: "
    << html_escape(suite.title)
    << "</title>\n<style>body{font-family:sans-serif;margin:2em;max-width:90em}"
       "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:4px 8px;"
       "vertical-align:top}td.known{max-width:28em;font-size:90%}</style></head><body>\n"
    << "<h1>" << html_escape(suite.title) << "</h1>\n"
    << "<p>Each fabric is verified with what is known of its sample (construction, fiber, "
       "colour space), never with its measured curve. Figures are RMS of ln(model / measured) "
       "over views up to 80&deg;: <b>shape</b> after one least-squares gain per channel, the "
       "same procedure for every model (the headline; &plusmn; the seed spread, in brackets "
       "the spread over the measurement's own fits where it has several); <b>paper's</b> "
       "one-point normalization (Voloboy et al. 2010: hinges on the normal-incidence, "
       "normal-view point); <b>absolute</b> (includes the colour level: comparable only where "
       "model and measurement share a colour space).</p>\n<table>\n<tr><th rowspan=\"2\">fabric"
       "</th><th rowspan=\"2\">what is known</th>";
  for (const SuiteModel& model : kSuiteModels) h << "<th colspan=\"3\">" << model.label << "</th>";
  h << "<th rowspan=\"2\">verdict</th></tr>\n<tr>";
  for (size_t k = 0; k < std::size(kSuiteModels); ++k)
    h << "<th>shape</th><th>paper's</th><th>absolute</th>";
  h << "</tr>\n";
  for (const auto& r : rows) {
    const nlohmann::json row = suite_row_json(r);
    h << "<tr><td><a href=\"" << html_escape(r.fabric.name) << "/index.html\">"
      << html_escape(r.fabric.name) << "</a></td><td class=\"known\">"
      << html_escape(r.fabric.known) << "<br><small>fiber " << html_escape(r.fabric.fiber)
      << "; colour space "
      << html_escape(r.fabric.colour_space.empty() ? "as the file says" : r.fabric.colour_space)
      << "</small></td>";
    if (row.contains("error")) {
      h << "<td colspan=\"" << 3 * std::size(kSuiteModels) + 1
        << "\">failed: " << html_escape(r.error) << "</td></tr>\n";
      continue;
    }
    for (const SuiteModel& model : kSuiteModels)
      h << model_cell(row["models"].contains(model.key) ? row["models"][model.key]
                                                        : nlohmann::json());
    h << "<td>" << html_escape(verdict_text(row)) << "</td></tr>\n";
  }
  h << "</table>\n</body></html>\n";
  return h.str();
}

}  // namespace weft
