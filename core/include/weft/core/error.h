#pragma once
// The one error type of the libraries: it names what was wrong and where (file, field), so the
// front end can print it and exit non-zero. Libraries never print and never exit.
#include <stdexcept>
#include <string>

namespace weft {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
  // "FILE: field 'FIELD': MESSAGE"; either part may be empty.
  Error(const std::string& file, const std::string& field, const std::string& message)
      : std::runtime_error(compose(file, field, message)) {}

 private:
  static std::string compose(const std::string& file, const std::string& field,
                             const std::string& message) {
    std::string out;
    if (!file.empty()) out += file + ": ";
    if (!field.empty()) out += "field '" + field + "': ";
    return out + message;
  }
};

}  // namespace weft
