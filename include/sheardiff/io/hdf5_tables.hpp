#pragma once
// Small result files made of whole datasets written once (analysis.h5, channel.h5), as
// opposed to the appended H5MD trajectory (io/h5md.hpp).
#include <hdf5.h>

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace sheardiff {

// Owns one hid_t and closes it with the matching H5?close.
struct H5Id {
  hid_t id;
  herr_t (*close)(hid_t);
  H5Id(hid_t i, herr_t (*c)(hid_t)) : id(i), close(c) {}
  H5Id(const H5Id&) = delete;
  H5Id& operator=(const H5Id&) = delete;
  ~H5Id() {
    if (id >= 0) close(id);
  }
};

// A float64 vector at `name` (intermediate groups created).
// With a unit and a description (attributes "unit" and "description", docs/outputs.md), so that
// the file says what it holds.
void write_vector(hid_t file, const std::string& name, const std::vector<double>& v,
                  const std::string& unit = "", const std::string& description = "");
// A scalar string attribute (ASCII, variable length).
void write_text_attribute(hid_t obj, const char* name, const std::string& text);

// rows x cols as float32, chunked and compressed (shuffle + deflate): for tables whose values
// carry a few significant digits, where float64 text or binary would be mostly noise.
// Every row must hold cols values.
void write_compressed_table(hid_t file, const std::string& name,
                            const std::vector<std::vector<double>>& rows, std::size_t cols,
                            const std::string& unit = "", const std::string& description = "");

void write_attribute(hid_t obj, const char* name, double x);

// A whole dataset of any rank, flattened row-major, as float64; throws naming the file and the
// dataset if either is missing.
std::vector<double> read_dataset(const std::filesystem::path& file, const std::string& name);

}  // namespace sheardiff
