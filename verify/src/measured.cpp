#include "weft/verify/measured.h"

#include <algorithm>
#include <array>
#include <fstream>
#include <map>

#include "weft/core/error.h"
#include "weft/core/install_paths.h"
#include "weft/core/params.h"

#ifndef WEFT_DATA_DIR
#define WEFT_DATA_DIR ""
#endif

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

}  // namespace

MeasuredInplane read_measured_inplane(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path);
  if (!in) throw Error(file, "", "cannot open the measured in-plane table");
  std::string line;
  std::vector<std::string> header;
  size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] == '#' || line.rfind("\"#", 0) == 0) continue;
    header = split_csv(line);
    break;
  }
  if (header.empty()) throw Error(file, "", "no header line (empty table)");
  const std::vector<std::string> needed = {"theta_i_deg", "theta_o_deg", "nbrdf_beta_R",
                                           "nbrdf_beta_G", "nbrdf_beta_B"};
  std::array<size_t, 5> col{};
  for (size_t k = 0; k < needed.size(); ++k) {
    const auto it = std::find(header.begin(), header.end(), needed[k]);
    if (it == header.end()) throw Error(file, needed[k], "missing column");
    col[k] = static_cast<size_t>(it - header.begin());
  }
  std::map<double, std::map<double, Rgb>> rows;  // theta_i -> view (paper's sign) -> beta
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line == "\r") continue;
    const auto f = split_csv(line);
    const std::string where = "line " + std::to_string(line_no);
    if (f.size() != header.size())
      throw Error(file, where,
                  std::to_string(f.size()) + " fields where the header has " +
                      std::to_string(header.size()));
    std::array<double, 5> v{};
    for (size_t k = 0; k < 5; ++k) v[k] = parse_number(f[col[k]], file, where + " " + needed[k]);
    if (v[0] < 0 || v[0] >= 90) throw Error(file, where + " theta_i_deg", "must lie in [0, 90)");
    if (v[1] <= -90 || v[1] >= 90)
      throw Error(file, where + " theta_o_deg", "must lie in (-90, 90)");
    for (size_t k = 2; k < 5; ++k)
      if (v[k] < 0) throw Error(file, where + " " + needed[k], "a radiance coefficient is >= 0");
    // The table's theta_o is negative on the mirror side, the paper's view positive (0.0 - x:
    // no negative zero).
    auto& curve = rows[v[0]];
    if (!curve.emplace(0.0 - v[1], Rgb(v[2], v[3], v[4])).second)
      throw Error(file, where, "duplicate row for this (theta_i_deg, theta_o_deg)");
  }
  if (rows.empty()) throw Error(file, "", "no data rows");
  MeasuredInplane m;
  m.file = file;
  for (const auto& [ti, views] : rows) {
    MeasuredCurve c;
    c.theta_i_deg = ti;
    for (const auto& [v, b] : views) {
      c.view_deg.push_back(v);
      c.beta.push_back(b);
    }
    m.curves.push_back(std::move(c));
  }
  return m;
}

std::filesystem::path bundled_measured_inplane() {
  std::string tried;
  const auto p = find_installed_file(WEFT_DATA_DIR, "materials",
                                     "measured/merl-red-fabric/inplane.csv", &tried);
  if (p.empty())
    throw Error("merl-red-fabric/inplane.csv", "--measured",
                "the bundled measurement is not found (tried: " + tried + ")");
  return p;
}

}  // namespace weft
