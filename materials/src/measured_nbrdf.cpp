#include "weft/materials/measured_nbrdf.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <system_error>

#include "weft/core/error.h"
#include "weft/core/install_paths.h"
#include "weft/core/math.h"
#include "weft/core/params.h"

namespace weft {
namespace {

struct Block {
  const char* name;
  int rows, cols;  // cols == 0: a vector of 'rows' numbers ("NAME n")
  double* dst;
};

}  // namespace

NbrdfNetwork NbrdfNetwork::load(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path);
  if (!in) throw Error(file, "", "cannot open the NBRDF weights file");
  // Strip comments; the rest is a stream of tokens.
  std::stringstream body;
  for (std::string line; std::getline(in, line);) {
    const auto hash = line.find('#');
    body << (hash == std::string::npos ? line : line.substr(0, hash)) << '\n';
  }
  NbrdfNetwork net;
  const Block blocks[] = {
      {"W1", kIn, kHidden, net.w1.data()},     {"b1", kHidden, 0, net.b1.data()},
      {"W2", kHidden, kHidden, net.w2.data()}, {"b2", kHidden, 0, net.b2.data()},
      {"W3", kHidden, kOut, net.w3.data()},    {"b3", kOut, 0, net.b3.data()}};
  for (const Block& b : blocks) {
    std::string name;
    if (!(body >> name)) throw Error(file, b.name, "missing block");
    if (name != b.name)
      throw Error(file, b.name,
                  "expected block " + std::string(b.name) + ", found \"" + name + "\"");
    int rows = 0, cols = 0;
    if (!(body >> rows)) throw Error(file, b.name, "missing size");
    if (b.cols > 0 && !(body >> cols)) throw Error(file, b.name, "missing column count");
    if (rows != b.rows || cols != b.cols)
      throw Error(file, b.name,
                  "has size " + std::to_string(rows) +
                      (b.cols ? " x " + std::to_string(cols) : "") + ", expected " +
                      std::to_string(b.rows) + (b.cols ? " x " + std::to_string(b.cols) : ""));
    const int count = b.rows * std::max(1, b.cols);
    for (int i = 0; i < count; ++i) {
      std::string token;
      if (!(body >> token))
        throw Error(
            file, b.name,
            "ends after " + std::to_string(i) + " of " + std::to_string(count) + " numbers");
      const auto v = finite_number(token);
      if (!v)
        throw Error(file, std::string(b.name) + "[" + std::to_string(i) + "]",
                    "\"" + token + "\" is not a finite number");
      b.dst[i] = *v;
    }
  }
  std::string extra;
  if (body >> extra) throw Error(file, "", "unexpected content after b3: \"" + extra + "\"");
  return net;
}

Rgb NbrdfNetwork::eval_upper(const Vec3& wo, const Vec3& wi) const {
  const Vec3 h = normalize(wo + wi);
  const double sin_th = std::sqrt(h.x * h.x + h.y * h.y), cos_th = h.z;
  const double phi_h = std::atan2(h.y, h.x);
  const double cp = std::cos(phi_h), sp = std::sin(phi_h);
  // d = R_y(-theta_h) R_z(-phi_h) wi.
  const Vec3 r{cp * wi.x + sp * wi.y, -sp * wi.x + cp * wi.y, wi.z};
  const Vec3 d{cos_th * r.x - sin_th * r.z, r.y, sin_th * r.x + cos_th * r.z};
  const double x[kIn] = {sin_th, 0.0, cos_th, d.x, d.y, d.z};

  double a1[kHidden], a2[kHidden];
  for (int j = 0; j < kHidden; ++j) {
    double s = b1[j];
    for (int i = 0; i < kIn; ++i) s += x[i] * w1[i * kHidden + j];
    a1[j] = std::max(0.0, s);
  }
  for (int k = 0; k < kHidden; ++k) {
    double s = b2[k];
    for (int j = 0; j < kHidden; ++j) s += a1[j] * w2[j * kHidden + k];
    a2[k] = std::max(0.0, s);
  }
  double out[kOut];
  for (int c = 0; c < kOut; ++c) {
    double s = b3[c];
    for (int k = 0; k < kHidden; ++k) s += a2[k] * w3[k * kOut + c];
    out[c] = std::max(0.0, std::exp(s) - 1);
  }
  return {out[0], out[1], out[2]};
}

// The folders of materials/data/measured (listed there in samples.json, made by make_inplane.py).
std::vector<std::string> measured_nbrdf_names() {
  return {"merl-red-fabric",           "merl-white-fabric",       "merl-red-fabric2",
          "merl-white-fabric2",        "merl-blue-fabric",        "merl-green-fabric",
          "merl-pink-fabric",          "merl-pink-fabric2",       "merl-pink-felt",
          "merl-beige-fabric",         "merl-black-fabric",       "merl-light-brown-fabric",
          "merl-dark-specular-fabric", "rgl-acrylic-felt-green",  "rgl-acrylic-felt-orange",
          "rgl-acrylic-felt-pink",     "rgl-acrylic-felt-purple", "rgl-acrylic-felt-white",
          "rgl-acrylic-felt-yellow",   "rgl-satin-blue",          "rgl-satin-gold",
          "rgl-satin-purple",          "rgl-satin-rosaline",      "rgl-satin-white"};
}

std::filesystem::path find_measured_nbrdf(const std::string& name) {
  namespace fs = std::filesystem;
  bool known = false;
  std::string valid;
  for (const auto& n : measured_nbrdf_names()) {
    known = known || n == name;
    valid += (valid.empty() ? "" : ", ") + n;
  }
  if (!known) throw Error("unknown measured material '" + name + "' (valid: " + valid + ")");
  std::string tried;
  const fs::path path =
      find_bundled_file(fs::path("materials/data/measured") / name / "nbrdf_weights.txt", &tried);
  if (path.empty())
    throw Error("data for measured material '" + name + "' not found (tried: " + tried + ")");
  return path;
}

Rgb MeasuredNbrdfBsdf::eval(const Vec3& wo, const Vec3& wi) const {
  if (!network || wo.z * wi.z <= 0) return Rgb(0.0);
  if (wo.z > 0) return network->eval_upper(wo, wi);
  return network->eval_upper({wo.x, wo.y, -wo.z}, {wi.x, wi.y, -wi.z});
}

double MeasuredNbrdfBsdf::pdf(const Vec3& wo, const Vec3& wi) const {
  if (!network || wo.z * wi.z <= 0) return 0;
  return std::abs(wi.z) * kInvPi;
}

std::optional<BsdfSample> MeasuredNbrdfBsdf::sample(const Vec3& wo, Vec2 u, double) const {
  if (!network || wo.z == 0) return std::nullopt;
  Vec3 wi = sample_cosine_hemisphere(u);
  if (wi.z <= 0) return std::nullopt;
  if (wo.z < 0) wi.z = -wi.z;
  const double p = std::abs(wi.z) * kInvPi;
  return BsdfSample{wi, eval(wo, wi) * (std::abs(wi.z) / p), p, false};
}

}  // namespace weft
