#pragma once
// What an export wrote and what the format could not carry, for the command to print.
#include <string>
#include <utility>
#include <vector>

namespace weft {

struct ExportReport {
  std::string format;                                   // "RGL .bsdf", "MDL .mbsdf", "glTF 2.0"
  std::vector<std::string> dropped;                     // what of the table the file does not carry
  std::vector<std::string> notes;                       // how it was made, what a reader needs
  std::vector<std::pair<std::string, double>> figures;  // named numbers (fit error, sizes)
};

}  // namespace weft
