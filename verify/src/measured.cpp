#include "weft/verify/measured.h"

#include <algorithm>
#include <array>
#include <fstream>
#include <map>
#include <optional>
#include <utility>

#include "common.h"
#include "weft/core/error.h"
#include "weft/core/install_paths.h"
#include "weft/core/math.h"
#include "weft/core/params.h"

namespace weft {
namespace {

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur.push_back(c);
    }
  }
  out.push_back(cur);
  return out;
}

double parse_number(const std::string& text, const std::string& file, const std::string& field) {
  if (const auto v = finite_number(text)) return *v;
  throw Error(file, field, "'" + text + "' is not a finite number");
}

// A comment line's colour space, where it states one ("# colour_space: camera", quoted or not).
std::optional<MeasuredColourSpace> comment_colour_space(std::string line, const std::string& file) {
  const auto trim = [](std::string& t, const char* chars) {
    t.erase(0, t.find_first_not_of(chars));
    const size_t end = t.find_last_not_of(chars);
    t.erase(end == std::string::npos ? 0 : end + 1);
  };
  trim(line, "\"# \t\r");
  const std::string key = "colour_space:";
  if (line.rfind(key, 0) != 0) return std::nullopt;
  std::string value = line.substr(key.size());
  trim(value, "\" \t\r");
  return parse_colour_space(value, file, "colour_space");
}

// The columns of a table: the angles and the reference fit (required), and the other fits whose
// three columns are all there (a fit with some of them is an error).
struct Columns {
  size_t theta_i = 0, theta_o = 0;
  std::vector<std::string> fit_names;         // "nbrdf" first
  std::vector<std::array<size_t, 3>> fit_at;  // [fit] -> R, G, B column
  std::vector<double> fit_scale;              // beta per unit of the column (1 or pi)
  std::vector<std::array<std::string, 3>> fit_columns;
};

Columns find_columns(const std::vector<std::string>& header, const std::string& file) {
  const auto find = [&](const std::string& name) -> std::optional<size_t> {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) return std::nullopt;
    return static_cast<size_t>(it - header.begin());
  };
  const auto need = [&](const std::string& name) {
    if (const auto k = find(name)) return *k;
    throw Error(file, name, "missing column");
  };
  Columns c;
  c.theta_i = need("theta_i_deg");
  c.theta_o = need("theta_o_deg");
  // The reference is beta itself; the other fits give f_r (1/sr), so beta = pi f_r.
  const std::array<std::pair<std::string, double>, 3> fits = {
      {{"nbrdf_beta_", 1.0}, {"sgd_fr_", kPi}, {"abc_fr_", kPi}}};
  for (const auto& [prefix, scale] : fits) {
    std::array<std::string, 3> names;
    std::array<std::optional<size_t>, 3> at;
    int present = 0;
    for (int k = 0; k < 3; ++k) {
      names[k] = prefix + "RGB"[k];
      at[k] = find(names[k]);
      present += at[k].has_value();
    }
    if (present == 0 && prefix != "nbrdf_beta_") continue;
    for (int k = 0; k < 3; ++k)
      if (!at[k]) throw Error(file, names[k], "missing column");
    c.fit_names.push_back(prefix.substr(0, prefix.find('_')));
    c.fit_at.push_back({*at[0], *at[1], *at[2]});
    c.fit_scale.push_back(scale);
    c.fit_columns.push_back(names);
  }
  return c;
}

// The table's rows: theta_i -> view (paper's sign) -> beta of every fit.
using Rows = std::map<double, std::map<double, std::vector<Rgb>>>;

void read_row(const std::vector<std::string>& f, const Columns& col, const std::string& file,
              const std::string& where, Rows& rows) {
  const double ti = parse_number(f[col.theta_i], file, where + " theta_i_deg");
  const double to = parse_number(f[col.theta_o], file, where + " theta_o_deg");
  if (ti < 0 || ti >= 90) throw Error(file, where + " theta_i_deg", "must lie in [0, 90)");
  if (to <= -90 || to >= 90) throw Error(file, where + " theta_o_deg", "must lie in (-90, 90)");
  std::vector<Rgb> betas;
  for (size_t j = 0; j < col.fit_at.size(); ++j) {
    Rgb b;
    for (int k = 0; k < 3; ++k) {
      const std::string field = where + " " + col.fit_columns[j][k];
      const double v = parse_number(f[col.fit_at[j][k]], file, field);
      if (v < 0) throw Error(file, field, "a radiance coefficient is >= 0");
      b[k] = v * col.fit_scale[j];
      if (b[k] > kMaxMeasuredBeta)
        throw Error(file, field,
                    "beta " + f[col.fit_at[j][k]] + " is absurd (above " + fmt(kMaxMeasuredBeta) +
                        "; a fabric's is of order 1): a unit or export error?");
    }
    betas.push_back(b);
  }
  // The limits before the row is stored, so that a huge table is refused as soon as it passes
  // them instead of being held in memory first.
  const auto at = rows.find(ti);
  if (at == rows.end() && rows.size() >= kMaxMeasuredIncidences)
    throw Error(file, where + " theta_i_deg",
                "more than " + std::to_string(kMaxMeasuredIncidences) +
                    " incidences (the limit of a measured table)");
  if (at != rows.end() && at->second.size() >= kMaxMeasuredViews)
    throw Error(file, where + " theta_o_deg",
                "more than " + std::to_string(kMaxMeasuredViews) + " views at theta_i_deg " +
                    fmt(ti, 6) + " (the limit of a measured table)");
  // The table's theta_o is negative on the mirror side, the paper's view positive (0.0 - x:
  // no negative zero).
  if (!rows[ti].emplace(0.0 - to, std::move(betas)).second)
    throw Error(file, where, "duplicate row for this (theta_i_deg, theta_o_deg)");
}

// A column that is zero at every row measured nothing (an empty export, a dark frame): every
// comparison with it is undefined, so it is refused rather than scored.
void check_not_all_zero(const Rows& rows, const Columns& col, const std::string& file) {
  for (size_t j = 0; j < col.fit_at.size(); ++j)
    for (int k = 0; k < 3; ++k) {
      bool any = false;
      for (const auto& [ti, views] : rows)
        for (const auto& [v, b] : views) any = any || b[j][k] > 0;
      if (!any)
        throw Error(file, col.fit_columns[j][k],
                    "zero at every row: nothing was measured in this channel");
    }
}

// The size on disk before any of it is read.
void check_file_size(const std::filesystem::path& path, const std::string& file) {
  std::error_code ec;
  const uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (!ec && bytes > kMaxMeasuredBytes)
    throw Error(file, "size",
                std::to_string(bytes) + " bytes; a measured in-plane table is at most " +
                    std::to_string(kMaxMeasuredBytes >> 20) + " MiB (" +
                    std::to_string(kMaxMeasuredIncidences) + " incidences of " +
                    std::to_string(kMaxMeasuredViews) + " views)");
}

MeasuredInplane measured_from_rows(const Rows& rows, const Columns& col, const std::string& file) {
  MeasuredInplane m;
  m.file = file;
  for (size_t j = 1; j < col.fit_names.size(); ++j) m.other_fits.push_back({col.fit_names[j], {}});
  for (const auto& [ti, views] : rows) {
    MeasuredCurve c;
    c.theta_i_deg = ti;
    for (auto& f : m.other_fits) f.beta.emplace_back();
    for (const auto& [v, b] : views) {
      c.view_deg.push_back(v);
      c.beta.push_back(b[0]);
      for (size_t j = 1; j < b.size(); ++j) m.other_fits[j - 1].beta.back().push_back(b[j]);
    }
    m.curves.push_back(std::move(c));
  }
  return m;
}

}  // namespace

MeasuredInplane read_measured_inplane(const std::filesystem::path& path) {
  const std::string file = path.string();
  check_file_size(path, file);
  std::ifstream in(path);
  if (!in) throw Error(file, "", "cannot open the measured in-plane table");
  std::string line;
  std::vector<std::string> header;
  size_t line_no = 0;
  std::optional<MeasuredColourSpace> space;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] == '#' || line.rfind("\"#", 0) == 0) {
      if (const auto c = comment_colour_space(line, file)) {
        if (space) throw Error(file, "colour_space", "given on two comment lines");
        space = c;
      }
      continue;
    }
    header = split_csv(line);
    break;
  }
  if (header.empty()) throw Error(file, "", "no header line (empty table)");
  const Columns col = find_columns(header, file);
  Rows rows;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line == "\r") continue;
    const auto f = split_csv(line);
    const std::string where = "line " + std::to_string(line_no);
    if (f.size() != header.size())
      throw Error(file, where,
                  std::to_string(f.size()) + " fields where the header has " +
                      std::to_string(header.size()));
    read_row(f, col, file, where, rows);
  }
  if (rows.empty()) throw Error(file, "", "no data rows");
  check_not_all_zero(rows, col, file);
  MeasuredInplane m = measured_from_rows(rows, col, file);
  m.colour_space = space.value_or(MeasuredColourSpace::kUnknown);
  return m;
}

std::string colour_space_name(MeasuredColourSpace c) {
  switch (c) {
    case MeasuredColourSpace::kCamera:
      return "camera";
    case MeasuredColourSpace::kSrgb:
      return "srgb";
    case MeasuredColourSpace::kUnknown:
      break;
  }
  return "unknown";
}

MeasuredColourSpace parse_colour_space(const std::string& text, const std::string& file,
                                       const std::string& field) {
  if (text == "camera") return MeasuredColourSpace::kCamera;
  if (text == "srgb") return MeasuredColourSpace::kSrgb;
  throw Error(file, field, "'" + text + "' is not a colour space: camera or srgb");
}

std::string not_comparable_note(MeasuredColourSpace c) {
  if (absolute_comparable(c)) return "";
  return c == MeasuredColourSpace::kCamera
             ? "not comparable: the measurement is in camera RGB, the models in linear sRGB"
             : "not comparable: the measurement's RGB space is unknown, the models are in linear "
               "sRGB";
}

std::vector<MeasuredFit> measured_fits(const MeasuredInplane& m) {
  std::vector<MeasuredFit> out(1);
  out[0].name = "nbrdf";
  for (const auto& c : m.curves) out[0].beta.push_back(c.beta);
  out.insert(out.end(), m.other_fits.begin(), m.other_fits.end());
  return out;
}

std::filesystem::path bundled_measured_inplane() {
  std::string tried;
  const auto p = find_bundled_file("materials/data/measured/merl-red-fabric/inplane.csv", &tried);
  if (p.empty())
    throw Error("merl-red-fabric/inplane.csv", "--measured",
                "the bundled measurement is not found (tried: " + tried + ")");
  return p;
}

}  // namespace weft
