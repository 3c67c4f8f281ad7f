#pragma once
// Radiance RGBE (.hdr) output of a render, for render_job.cpp; written by image.cpp with the other
// image writers. (Private to the library until image.h is next changed.)
#include <filesystem>

#include "weft/integrators/image.h"

namespace weft {

// Linear RGB as Radiance RGBE (.hdr): 8-bit mantissas under a shared exponent, so each channel
// keeps about 1/256 of the pixel's largest one; negative values are written as 0. No metadata.
void write_hdr(const std::filesystem::path& path, const Image& image);

}  // namespace weft
