#pragma once
// The one reader of JSON parameters (scene descriptions, material parameters, fiber specs, render
// and sweep settings). It reads an object field by field with errors that name the file and the
// JSON path of the field, remembers which keys were asked for, and finish() rejects the rest:
// a misspelt or misplaced key is an error naming its path, never a silent default. A key that is
// valid but has no effect in the configuration given is rejected by reject_unused().
//
// The code that uses a setting reads it: a library hands the sub-object it does not own to the
// library that does (ParamReader::object), and each calls finish() on what it read.
#include <cstdint>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "weft/core/spectrum.h"
#include "weft/core/vec.h"

namespace weft {

// JSON nested deeper than this is refused before it is parsed: parsing is iterative, but copying,
// comparing and printing a value recurse once per level (and so does tinygltf), so a file of
// 10^5 '[' would overflow the stack. Real inputs nest fewer than 10 levels.
inline constexpr int kMaxJsonDepth = 128;

// Throws weft::Error(file, "", ...) naming the line and column where 'text' nests deeper than
// kMaxJsonDepth arrays and objects. Scans bytes only (strings and escapes are skipped).
void check_json_depth(std::string_view text, const std::string& file);

// The one JSON parser of user files: check_json_depth, then a strict parse whose errors name the
// file and, where it is known, the JSON path of the value (e.g. a number out of the range of a
// double: "scene.json: field 'lights[0].irradiance': number 1e400 is out of range").
nlohmann::json parse_json(std::string_view text, const std::string& file);

// The one strict parser of a number in text (options, CSV cells, weight files): the finite number
// that is the whole of 'text', or nothing ("1.5x", "nan", "inf", "").
std::optional<double> finite_number(const std::string& text);
// The shortest-safe text of x that finite_number reads back to the same bits ("%.17g"), for
// numbers kept in files' headers.
std::string exact_number(double x);

// Parses "a:b:step" (inclusive) or a single value or "a,b,c" into a list of numbers; at most
// max_count of them (a range's count is checked before the list is built), no empty items.
// weft::Error naming 'option_name' otherwise.
inline constexpr size_t kMaxRangeCount = 100000;
std::vector<double> parse_range(const std::string& text, const std::string& option_name,
                                size_t max_count = kMaxRangeCount);

class ParamReader {
 public:
  // 'file' names the source in errors; 'path' is the JSON path of this object ("" at the root).
  // Throws weft::Error unless j is an object.
  ParamReader(const nlohmann::json& j, std::string file, std::string path);

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  // The JSON path of a key of this object, e.g. "materials.seat.params.alpha".
  std::string field(const std::string& key) const;

  // Whether the key is present; counts as asking for it.
  bool has(const std::string& key);
  // The raw value; Error "is required" when absent.
  const nlohmann::json& at(const std::string& key);
  // A nested object, read by its own reader (whose finish() checks its keys).
  ParamReader object(const std::string& key);

  // Finite numbers in [lo, hi]; the overloads with a fallback return it when the key is absent.
  double number(const std::string& key, double lo, double hi);
  double number(const std::string& key, double fallback, double lo, double hi);
  // Integers in [lo, hi]. Written as an integer or as an integral number (1e5 is 100000).
  int64_t integer(const std::string& key, int64_t lo, int64_t hi);
  int64_t integer(const std::string& key, int64_t fallback, int64_t lo, int64_t hi);
  uint64_t count(const std::string& key, uint64_t lo, uint64_t hi);
  uint64_t count(const std::string& key, uint64_t fallback, uint64_t lo, uint64_t hi);
  // An array of at most max_size counts, each in [lo, hi]: the length is checked before any
  // element is converted, and each element as count() checks it.
  std::vector<uint64_t> counts(const std::string& key, size_t max_size, uint64_t lo, uint64_t hi);
  bool boolean(const std::string& key, bool fallback);
  // A non-empty string.
  std::string string(const std::string& key);
  std::string string(const std::string& key, const std::string& fallback);
  // A string that may be empty (where the writer stores an unset option as ""); required.
  std::string string_or_empty(const std::string& key);
  // One of 'valid'; the error lists them.
  std::string choice(const std::string& key, const std::string& fallback,
                     std::initializer_list<const char*> valid);
  Vec3 vec3(const std::string& key);
  Vec3 unit_vec3(const std::string& key);
  // A colour: a number (grey) or [r, g, b], each finite and in [lo, hi].
  Rgb rgb(const std::string& key, double lo, double hi);
  Rgb rgb(const std::string& key, const Rgb& fallback, double lo, double hi);

  // A key that is valid elsewhere but has no effect here: Error "<why>" when present.
  void reject_unused(const std::string& key, const std::string& why);
  // Error on the first key that nobody asked for, listing the keys this object knows.
  void finish() const;

  // Checks of a value found elsewhere (array elements): 'name' is its full path.
  double check_number(const nlohmann::json& v, const std::string& name, double lo, double hi) const;
  Vec3 check_vec3(const nlohmann::json& v, const std::string& name) const;
  // Shortest readable form of a number for messages.
  static std::string fmt(double d);

 private:
  int64_t check_integer(const nlohmann::json& v, const std::string& name, int64_t lo,
                        int64_t hi) const;
  uint64_t check_count(const nlohmann::json& v, const std::string& name, uint64_t lo,
                       uint64_t hi) const;

  const nlohmann::json& j_;
  std::string file_, path_;
  std::set<std::string> asked_;
};

}  // namespace weft
