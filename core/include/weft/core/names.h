#pragma once
// Choices a user names (a method, an estimator, a level, a model): one table per choice of
// value -> name -> label, read by the command line, the Python module and the reports alike, so
// that a name is spelt in one place and an unknown one is answered with the valid ones.
#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "weft/core/error.h"

namespace weft {

template <class E>
struct NamedValue {
  E value;
  const char* name;   // as the user types it
  const char* label;  // as a report or a plot legend shows it
};

template <class E, size_t N>
using NameTable = std::array<NamedValue<E>, N>;

// The names in table order, for a command line's list of allowed values.
template <class E, size_t N>
std::vector<std::string> names_of(const NameTable<E, N>& table) {
  std::vector<std::string> out;
  for (const auto& e : table) out.emplace_back(e.name);
  return out;
}

// "a, b or c", for messages.
template <class E, size_t N>
std::string name_list(const NameTable<E, N>& table) {
  std::string out;
  for (size_t i = 0; i < N; ++i)
    out += std::string(i == 0 ? "" : i + 1 == N ? " or " : ", ") + "'" + table[i].name + "'";
  return out;
}

template <class E, size_t N>
const NamedValue<E>& entry_of(const NameTable<E, N>& table, E value) {
  for (const auto& e : table)
    if (e.value == value) return e;
  throw Error("", "", "no name for this value");  // a table missing a value: a bug
}

template <class E, size_t N>
const char* name_of(const NameTable<E, N>& table, E value) {
  return entry_of(table, value).name;
}

template <class E, size_t N>
const char* label_of(const NameTable<E, N>& table, E value) {
  return entry_of(table, value).label;
}

// The value of 'name'; weft::Error(file, field, "must be 'a', 'b' or 'c', got 'x'") otherwise.
template <class E, size_t N>
E value_of(const NameTable<E, N>& table, std::string_view name, const std::string& file,
           const std::string& field) {
  for (const auto& e : table)
    if (name == e.name) return e.value;
  throw Error(file, field, "must be " + name_list(table) + ", got '" + std::string(name) + "'");
}

}  // namespace weft
