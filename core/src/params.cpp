#include "weft/core/params.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "weft/core/error.h"

namespace weft {
namespace {

// Builds the value like nlohmann's own DOM parser and keeps the JSON path of the value being read,
// so that an error can name it.
class PathTrackingSax : public nlohmann::json_sax<nlohmann::json> {
 public:
  using json = nlohmann::json;
  PathTrackingSax(json& root, const std::string& file) : dom_(root, true), file_(file) {}

  bool null() override { return value(dom_.null()); }
  bool boolean(bool v) override { return value(dom_.boolean(v)); }
  bool number_integer(number_integer_t v) override { return value(dom_.number_integer(v)); }
  bool number_unsigned(number_unsigned_t v) override { return value(dom_.number_unsigned(v)); }
  bool number_float(number_float_t v, const string_t& s) override {
    return value(dom_.number_float(v, s));
  }
  bool string(string_t& v) override { return value(dom_.string(v)); }
  bool binary(binary_t& v) override { return value(dom_.binary(v)); }
  bool start_object(std::size_t n) override {
    frames_.push_back({false, 0, ""});
    return dom_.start_object(n);
  }
  bool key(string_t& k) override {
    frames_.back().key = k;
    return dom_.key(k);
  }
  bool end_object() override {
    frames_.pop_back();
    return value(dom_.end_object());
  }
  bool start_array(std::size_t n) override {
    frames_.push_back({true, 0, ""});
    return dom_.start_array(n);
  }
  bool end_array() override {
    frames_.pop_back();
    return value(dom_.end_array());
  }
  bool parse_error(std::size_t position, const std::string& token,
                   const nlohmann::detail::exception& ex) override {
    (void)position;
    if (ex.id == 406)  // a number nlohmann cannot hold (out of the range of a double)
      throw Error(file_, path(), "number " + token + " is out of range (largest: 1.8e308)");
    throw Error(file_, path(), std::string("invalid JSON: ") + ex.what());
  }

 private:
  struct Frame {
    bool array;
    size_t index;  // arrays: the element being read
    std::string key;
  };
  // A value ended: the next one of an array has the next index.
  bool value(bool ok) {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
    return ok;
  }
  std::string path() const {
    std::string p;
    for (const Frame& f : frames_) {
      if (f.array)
        p += "[" + std::to_string(f.index) + "]";
      else if (!f.key.empty())
        p += (p.empty() ? "" : ".") + f.key;
    }
    return p;
  }

  nlohmann::detail::json_sax_dom_parser<json> dom_;
  const std::string& file_;
  std::vector<Frame> frames_;
};

}  // namespace

void check_json_depth(std::string_view text, const std::string& file) {
  int depth = 0;
  size_t line = 1, column = 0;
  bool in_string = false, escaped = false;
  for (const char c : text) {
    ++column;
    if (c == '\n') ++line, column = 0;
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth)
        throw Error(file, "",
                    "JSON nested deeper than " + std::to_string(kMaxJsonDepth) +
                        " arrays and objects (at line " + std::to_string(line) + ", column " +
                        std::to_string(column) + ")");
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
}

std::string exact_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

std::optional<double> finite_number(const std::string& text) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (...) {
    return std::nullopt;
  }
  if (used == 0 || used != text.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::vector<double> parse_range(const std::string& text, const std::string& option_name,
                                size_t max_count) {
  auto to_number = [&](const std::string& s) {
    if (const auto v = finite_number(s)) return *v;
    throw Error("", option_name, "'" + text + "' is not a number or range a:b:step");
  };
  std::vector<double> out;
  if (text.find(':') != std::string::npos) {
    std::vector<std::string> parts;
    std::stringstream ss(text);
    std::string p;
    while (std::getline(ss, p, ':')) parts.push_back(p);
    if (parts.size() != 3)
      throw Error("", option_name, "range must be a:b:step, got '" + text + "'");
    const double a = to_number(parts[0]), b = to_number(parts[1]), step = to_number(parts[2]);
    if (!(step > 0) || b < a) throw Error("", option_name, "range needs a <= b and step > 0");
    const double count = std::floor((b - a) / step + 1e-9) + 1;  // finite: a, b and step are
    if (count > static_cast<double>(max_count))
      throw Error("", option_name,
                  "range '" + text + "' has " + ParamReader::fmt(count) + " values, more than " +
                      std::to_string(max_count));
    const long n = static_cast<long>(count) - 1;
    for (long i = 0; i <= n; ++i) out.push_back(a + step * i);
    return out;
  }
  std::stringstream ss(text);
  std::string p;
  // getline drops a trailing empty item ("1,2,"): count the commas, refuse every empty item.
  const size_t items = static_cast<size_t>(std::count(text.begin(), text.end(), ',')) + 1;
  if (items > max_count)
    throw Error(
        "", option_name,
        "lists " + std::to_string(items) + " values, more than " + std::to_string(max_count));
  while (std::getline(ss, p, ',')) {
    if (p.empty()) break;
    out.push_back(to_number(p));
  }
  if (out.size() != items)
    throw Error("", option_name, "'" + text + "' has an empty item (a stray comma)");
  return out;
}

nlohmann::json parse_json(std::string_view text, const std::string& file) {
  check_json_depth(text, file);
  nlohmann::json root;
  PathTrackingSax sax(root, file);
  nlohmann::json::sax_parse(text, &sax);
  return root;
}

ParamReader::ParamReader(const nlohmann::json& j, std::string file, std::string path)
    : j_(j), file_(std::move(file)), path_(std::move(path)) {
  if (!j_.is_object())
    throw Error(file_, path_.empty() ? "(root)" : path_, "must be a JSON object");
}

std::string ParamReader::field(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

bool ParamReader::has(const std::string& key) {
  asked_.insert(key);
  return j_.contains(key);
}

const nlohmann::json& ParamReader::at(const std::string& key) {
  asked_.insert(key);
  if (!j_.contains(key)) throw Error(file_, field(key), "is required");
  return j_.at(key);
}

ParamReader ParamReader::object(const std::string& key) {
  return ParamReader(at(key), file_, field(key));
}

double ParamReader::number(const std::string& key, double lo, double hi) {
  return check_number(at(key), field(key), lo, hi);
}

double ParamReader::number(const std::string& key, double fallback, double lo, double hi) {
  return has(key) ? number(key, lo, hi) : fallback;
}

int64_t ParamReader::integer(const std::string& key, int64_t lo, int64_t hi) {
  return check_integer(at(key), field(key), lo, hi);
}

int64_t ParamReader::integer(const std::string& key, int64_t fallback, int64_t lo, int64_t hi) {
  return has(key) ? integer(key, lo, hi) : fallback;
}

uint64_t ParamReader::count(const std::string& key, uint64_t lo, uint64_t hi) {
  return check_count(at(key), field(key), lo, hi);
}

uint64_t ParamReader::count(const std::string& key, uint64_t fallback, uint64_t lo, uint64_t hi) {
  return has(key) ? count(key, lo, hi) : fallback;
}

std::vector<uint64_t> ParamReader::counts(const std::string& key, size_t max_size, uint64_t lo,
                                          uint64_t hi) {
  const nlohmann::json& v = at(key);
  if (!v.is_array()) throw Error(file_, field(key), "must be an array of whole numbers");
  if (v.size() > max_size)
    throw Error(file_, field(key),
                "has " + std::to_string(v.size()) + " entries, at most " +
                    std::to_string(max_size) + " allowed");
  std::vector<uint64_t> out;
  out.reserve(v.size());
  for (size_t i = 0; i < v.size(); ++i)
    out.push_back(check_count(v[i], field(key) + "[" + std::to_string(i) + "]", lo, hi));
  return out;
}

bool ParamReader::boolean(const std::string& key, bool fallback) {
  if (!has(key)) return fallback;
  const auto& v = at(key);
  if (!v.is_boolean()) throw Error(file_, field(key), "must be true or false");
  return v.get<bool>();
}

std::string ParamReader::string(const std::string& key) {
  std::string s = string_or_empty(key);
  if (s.empty()) throw Error(file_, field(key), "must not be empty");
  return s;
}

std::string ParamReader::string_or_empty(const std::string& key) {
  const auto& v = at(key);
  if (!v.is_string()) throw Error(file_, field(key), "must be a string");
  return v.get<std::string>();
}

std::string ParamReader::string(const std::string& key, const std::string& fallback) {
  return has(key) ? string(key) : fallback;
}

std::string ParamReader::choice(const std::string& key, const std::string& fallback,
                                std::initializer_list<const char*> valid) {
  const std::string s = string(key, fallback);
  std::string list;
  for (const char* v : valid) {
    if (s == v) return s;
    list += std::string(list.empty() ? "" : ", ") + v;
  }
  throw Error(file_, field(key), "unknown value '" + s + "' (valid: " + list + ")");
}

Vec3 ParamReader::vec3(const std::string& key) {
  return check_vec3(at(key), field(key));
}

Vec3 ParamReader::unit_vec3(const std::string& key) {
  const Vec3 v = vec3(key);
  const double len = length(v);
  if (!(len > 0)) throw Error(file_, field(key), "must not be the zero vector");
  return v / len;
}

Rgb ParamReader::rgb(const std::string& key, double lo, double hi) {
  const auto& v = at(key);
  if (v.is_array()) {
    if (v.size() != 3) throw Error(file_, field(key), "needs 3 components");
    return {check_number(v[0], field(key) + "[0]", lo, hi),
            check_number(v[1], field(key) + "[1]", lo, hi),
            check_number(v[2], field(key) + "[2]", lo, hi)};
  }
  return Rgb(check_number(v, field(key), lo, hi));
}

Rgb ParamReader::rgb(const std::string& key, const Rgb& fallback, double lo, double hi) {
  return has(key) ? rgb(key, lo, hi) : fallback;
}

void ParamReader::reject_unused(const std::string& key, const std::string& why) {
  if (has(key)) throw Error(file_, field(key), why);
}

void ParamReader::finish() const {
  for (const auto& [key, value] : j_.items()) {
    if (asked_.count(key)) continue;
    std::string known;
    for (const auto& k : asked_) known += (known.empty() ? "" : ", ") + k;
    throw Error(file_, field(key),
                "unknown key" + (known.empty() ? std::string(" (this object takes no keys)")
                                               : " (known here: " + known + ")"));
  }
}

double ParamReader::check_number(const nlohmann::json& v, const std::string& name, double lo,
                                 double hi) const {
  if (!v.is_number()) throw Error(file_, name, "must be a number");
  const double d = v.get<double>();
  if (!std::isfinite(d)) throw Error(file_, name, "must be finite");
  if (d < lo || d > hi)
    throw Error(file_, name, "must lie in [" + fmt(lo) + ", " + fmt(hi) + "], got " + fmt(d));
  return d;
}

int64_t ParamReader::check_integer(const nlohmann::json& v, const std::string& name, int64_t lo,
                                   int64_t hi) const {
  const double d = check_number(v, name, -9.2e18, 9.2e18);
  if (d != std::floor(d)) throw Error(file_, name, "must be an integer, got " + fmt(d));
  const auto x = v.is_number_integer() ? v.get<int64_t>() : static_cast<int64_t>(d);
  if (x < lo || x > hi)
    throw Error(file_, name,
                "must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                    std::to_string(x));
  return x;
}

uint64_t ParamReader::check_count(const nlohmann::json& v, const std::string& name, uint64_t lo,
                                  uint64_t hi) const {
  auto out_of_range = [&](const std::string& got) {
    return Error(
        file_, name,
        "must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + got);
  };
  if (v.is_number_unsigned()) {
    const uint64_t x = v.get<uint64_t>();
    if (x < lo || x > hi) throw out_of_range(std::to_string(x));
    return x;
  }
  // Negative integers, integral doubles (1e5) and everything else: checked as doubles before
  // any conversion, so an out-of-range value never reaches a cast.
  const double d = check_number(v, name, -1e300, 1e300);
  if (d != std::floor(d)) throw Error(file_, name, "must be an integer, got " + fmt(d));
  // 2^64 itself compares equal to hi = 2^64 - 1 as a double, and would overflow the cast.
  if (d < static_cast<double>(lo) || d > static_cast<double>(hi) || d >= 0x1p64)
    throw out_of_range(fmt(d));
  const auto x = static_cast<uint64_t>(d);
  if (x > hi) throw out_of_range(fmt(d));
  return x;
}

Vec3 ParamReader::check_vec3(const nlohmann::json& v, const std::string& name) const {
  if (!v.is_array() || v.size() != 3) throw Error(file_, name, "must be an array of 3 numbers");
  return {check_number(v[0], name + "[0]", -1e30, 1e30),
          check_number(v[1], name + "[1]", -1e30, 1e30),
          check_number(v[2], name + "[2]", -1e30, 1e30)};
}

std::string ParamReader::fmt(double d) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", d);
  return buf;
}

}  // namespace weft
