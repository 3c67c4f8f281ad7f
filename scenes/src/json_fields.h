#pragma once
// Reading a JSON object field by field with errors that name the file and the field path, and a
// final check that rejects keys nobody asked for (misspellings are errors, not silent defaults).
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>

#include "weft/core/error.h"
#include "weft/core/spectrum.h"
#include "weft/core/vec.h"

namespace weft::detail {

class Fields {
 public:
  Fields(const nlohmann::json& j, std::string file, std::string path)
      : j_(j), file_(std::move(file)), path_(std::move(path)) {
    if (!j_.is_object()) throw Error(file_, path_, "must be a JSON object");
  }

  std::string field(const std::string& key) const {
    return path_.empty() ? key : path_ + "." + key;
  }
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  bool has(const std::string& key) {
    used_.insert(key);
    return j_.contains(key);
  }
  const nlohmann::json& at(const std::string& key) {
    used_.insert(key);
    if (!j_.contains(key)) throw Error(file_, field(key), "is required");
    return j_.at(key);
  }
  Fields object(const std::string& key) { return Fields(at(key), file_, field(key)); }

  double number(const std::string& key, double lo, double hi) {
    return check_number(at(key), field(key), lo, hi);
  }
  double number(const std::string& key, double fallback, double lo, double hi) {
    return has(key) ? number(key, lo, hi) : fallback;
  }
  int integer(const std::string& key, int fallback, int lo, int hi) {
    if (!has(key)) return fallback;
    const auto& v = at(key);
    if (!v.is_number_integer()) throw Error(file_, field(key), "must be an integer");
    const auto x = v.get<int64_t>();
    if (x < lo || x > hi)
      throw Error(file_, field(key),
                  "must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return static_cast<int>(x);
  }
  uint64_t unsigned_integer(const std::string& key, uint64_t fallback) {
    if (!has(key)) return fallback;
    const auto& v = at(key);
    if (!v.is_number_unsigned()) throw Error(file_, field(key), "must be a non-negative integer");
    return v.get<uint64_t>();
  }
  bool boolean(const std::string& key, bool fallback) {
    if (!has(key)) return fallback;
    const auto& v = at(key);
    if (!v.is_boolean()) throw Error(file_, field(key), "must be true or false");
    return v.get<bool>();
  }
  std::string string(const std::string& key) {
    const auto& v = at(key);
    if (!v.is_string()) throw Error(file_, field(key), "must be a string");
    return v.get<std::string>();
  }
  Vec3 vec3(const std::string& key) { return check_vec3(at(key), field(key)); }
  Vec3 unit_vec3(const std::string& key) {
    const Vec3 v = vec3(key);
    const double len = length(v);
    if (!(len > 0)) throw Error(file_, field(key), "must not be the zero vector");
    return v / len;
  }
  // A colour: a number (grey) or [r, g, b], each finite and in [lo, hi].
  Rgb rgb(const std::string& key, double lo, double hi) {
    const auto& v = at(key);
    if (v.is_array()) {
      if (v.size() != 3) throw Error(file_, field(key), "needs 3 components");
      return {check_number(v[0], field(key) + "[0]", lo, hi),
              check_number(v[1], field(key) + "[1]", lo, hi),
              check_number(v[2], field(key) + "[2]", lo, hi)};
    }
    return Rgb(check_number(v, field(key), lo, hi));
  }

  // Throws on the first key that was never asked for.
  void finish() const {
    for (const auto& [key, value] : j_.items())
      if (!used_.count(key)) throw Error(file_, field(key), "unknown key");
  }

  double check_number(const nlohmann::json& v, const std::string& name, double lo,
                      double hi) const {
    if (!v.is_number()) throw Error(file_, name, "must be a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) throw Error(file_, name, "must be finite");
    if (d < lo || d > hi)
      throw Error(file_, name, "must lie in [" + fmt(lo) + ", " + fmt(hi) + "], got " + fmt(d));
    return d;
  }
  Vec3 check_vec3(const nlohmann::json& v, const std::string& name) const {
    if (!v.is_array() || v.size() != 3) throw Error(file_, name, "must be an array of 3 numbers");
    return {check_number(v[0], name + "[0]", -1e30, 1e30),
            check_number(v[1], name + "[1]", -1e30, 1e30),
            check_number(v[2], name + "[2]", -1e30, 1e30)};
  }
  static std::string fmt(double d) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", d);
    return buf;
  }

 private:
  const nlohmann::json& j_;
  std::string file_, path_;
  std::set<std::string> used_;
};

}  // namespace weft::detail
