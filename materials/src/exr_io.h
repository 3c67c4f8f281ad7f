#pragma once
// The OpenEXR pieces the table formats share (the BSDF table, bsdf_table_exr.cpp, and the weave
// table, weave_table.cpp): a header walk that refuses sizes the file cannot hold before OpenEXR
// allocates them, typed attributes, channel checks, and one interleaved FLOAT image read and
// written with its FNV-1a checksum. Private to materials. Every check throws
// weft::Error(file, field, ...).
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace weft::exr_io {

// The file must exist and begin with OpenEXR's magic number.
void check_magic(const std::filesystem::path& path, const std::string& file);
// Every attribute's size must fit in the file, and the data window in max_width x max_height.
void check_header(const std::filesystem::path& path, const std::string& file, int64_t max_width,
                  int64_t max_height);
int int_attribute(const Imf::Header& h, const std::string& file, const char* name);
std::string string_attribute(const Imf::Header& h, const std::string& file, const char* name);
// The data window must be width x height from (0, 0); 'why' ends the message ("resolution 4").
void check_data_window(const Imf::Header& h, const std::string& file, int width, int height,
                       const std::string& why);
// pixel_bytes must fit in what the file can hold compressed; 'what' starts the message.
void check_fits_file(const std::filesystem::path& path, const std::string& file,
                     const std::string& field, double pixel_bytes, const std::string& what);
// The file's channels must be exactly 'names', each 32-bit FLOAT ('bands' for the message).
void check_channels(const Imf::Header& h, const std::string& file,
                    const std::vector<std::string>& names, const std::string& bands);
// The pixels [row][column][channel], checked against the attribute values_fnv1a64. The caller
// has checked the data window and the size against the file first.
std::vector<float> read_pixels(Imf::InputFile& in, const std::string& file,
                               const std::vector<std::string>& names, int width, int height);
// Writes 'values' [row][column][channel] into 'tmp' with the header's data window and attributes,
// adding the channels, ZIP compression (lossless: round trips are bit-exact) and values_fnv1a64.
void write_image(const std::filesystem::path& tmp, Imf::Header& header,
                 const std::vector<std::string>& names, const std::vector<float>& values);
// The header's string attributes not 'reserved': a table's metadata.
std::map<std::string, std::string> string_attributes(
    const Imf::Header& h, const std::function<bool(const std::string&)>& reserved);
// 64-bit FNV-1a over the values' bytes (IEEE binary32, little-endian, in order), 16 hex digits.
std::string checksum(std::span<const float> values);
// "R","G","B" for 3 channels, else "w390".."w710" (one per 10 nm band).
std::vector<std::string> channel_names(int channels);

}  // namespace weft::exr_io
