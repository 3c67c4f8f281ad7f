// The preview's in-plane plot, drawn as SVG text so that the page needs no script to show it: every
// incidence is drawn, one shown at a time; the page's control (viewer/inplane.js) switches them.
#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "weft/exchange/preview_html.h"
#include "weft/materials/table_inplane.h"

namespace weft {
namespace {

constexpr double kWidthPx = 520, kHeightPx = 340;
constexpr double kLeftPx = 56, kRightPx = 130, kTopPx = 16, kBottomPx = 44;  // margins
constexpr int kAzimuths = 16;  // the isotropic average, as verify's curves and the exporters
constexpr std::array<const char*, 3> kChannelColour = {"#d62728", "#2ca02c", "#1f77b4"};

// A round step for an axis spanning 'span': 1, 2 or 5 times a power of ten, about 5 ticks.
double tick_step(double span) {
  const double raw = span / 5, p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * p >= raw) return m * p;
  return 10 * p;
}

std::string axes(double beta_max, double x0, double y0, double w, double h) {
  std::ostringstream s;
  s << "<rect x='" << x0 << "' y='" << kTopPx << "' width='" << w << "' height='" << h
    << "' fill='#fff' stroke='#444'/>\n";
  for (int v = -90; v <= 90; v += 30) {
    const double x = x0 + (v + 90) / 180.0 * w;
    s << "<line x1='" << x << "' y1='" << y0 << "' x2='" << x << "' y2='" << y0 + 5
      << "' stroke='#444'/><text x='" << x << "' y='" << y0 + 18 << "' text-anchor='middle'>" << v
      << "</text>\n";
  }
  const double step = tick_step(beta_max);
  for (double b = 0; b <= beta_max * (1 + 1e-9); b += step) {
    const double y = y0 - b / beta_max * h;
    s << "<line x1='" << x0 - 5 << "' y1='" << y << "' x2='" << x0 << "' y2='" << y
      << "' stroke='#444'/><text x='" << x0 - 8 << "' y='" << y + 4 << "' text-anchor='end'>" << b
      << "</text>\n";
  }
  s << "<text x='" << x0 + w / 2 << "' y='" << kHeightPx - 6
    << "' text-anchor='middle'>view zenith (deg, &gt; 0 on the mirror side)</text>\n"
    << "<text transform='translate(14 " << kTopPx + h / 2
    << ") rotate(-90)' text-anchor='middle'>&#946; = &#960; f</text>\n";
  return s.str();
}

}  // namespace

std::vector<double> preview_incidences_deg() {
  std::vector<double> out;
  for (int t = 0; t < 90; t += 5) out.push_back(t);
  return out;
}

std::string inplane_svg(const TabulatedBsdfTable& table, const std::vector<double>& incidences_deg,
                        double shown_deg) {
  const TableReader rgb = table_to_rgb(TableReader(table));
  std::vector<double> views_deg;
  for (int v = -89; v <= 89; ++v) views_deg.push_back(v);
  std::vector<std::vector<Rgb>> curves;
  double beta_max = 0;
  for (double ti : incidences_deg) {
    curves.push_back(inplane_beta(rgb, ti, views_deg, kAzimuths));
    for (const Rgb& b : curves.back()) beta_max = std::max({beta_max, b.r, b.g, b.b});
  }
  // One scale for every incidence, so that switching among them shows how much the light
  // returned changes, not only its shape.
  beta_max = beta_max > 0 ? std::ceil(beta_max / tick_step(beta_max)) * tick_step(beta_max) : 1;
  const double w = kWidthPx - kLeftPx - kRightPx, h = kHeightPx - kTopPx - kBottomPx;
  const double x0 = kLeftPx, y0 = kTopPx + h, lx = kWidthPx - kRightPx;
  std::ostringstream s;
  s << "<svg id='weft-inplane' width='" << kWidthPx << "' height='" << kHeightPx
    << "' viewBox='0 0 " << kWidthPx << ' ' << kHeightPx
    << "' font-family='sans-serif' font-size='12' role='img'>\n"
    << axes(beta_max, x0, y0, w, h);
  static constexpr std::array<const char*, 3> kChannel = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    const double ly = kTopPx + 34 + 20 * c;
    s << "<line x1='" << lx + 10 << "' y1='" << ly << "' x2='" << lx + 40 << "' y2='" << ly
      << "' stroke='" << kChannelColour[c] << "' stroke-width='1.5'/><text x='" << lx + 46
      << "' y='" << ly + 4 << "'>" << kChannel[c] << "</text>\n";
  }
  // The incidence nearest 'shown_deg' is the one a page without script shows.
  size_t shown = 0;
  for (size_t i = 0; i < incidences_deg.size(); ++i)
    if (std::abs(incidences_deg[i] - shown_deg) < std::abs(incidences_deg[shown] - shown_deg))
      shown = i;
  for (size_t i = 0; i < curves.size(); ++i) {
    s << "<g class='weft-incidence' data-incidence='" << incidences_deg[i] << "' display='"
      << (i == shown ? "inline" : "none") << "'>\n<text x='" << lx + 10 << "' y='" << kTopPx + 10
      << "'>&#952;i = " << incidences_deg[i] << "&#176;</text>\n";
    for (int c = 0; c < 3; ++c) {
      s << "<polyline fill='none' stroke-width='1.5' stroke='" << kChannelColour[c] << "' points='";
      for (size_t v = 0; v < views_deg.size(); ++v) {
        // Clipped to the frame: a negative component (a spectral colour outside sRGB) sits on 0.
        const double b = std::clamp(curves[i][v][c], 0.0, beta_max);
        s << x0 + (views_deg[v] + 90) / 180 * w << ',' << y0 - b / beta_max * h << ' ';
      }
      s << "'/>\n";
    }
    s << "</g>\n";
  }
  s << "</svg>\n";
  return s.str();
}

}  // namespace weft
