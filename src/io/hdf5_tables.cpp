#include "sheardiff/io/hdf5_tables.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace sheardiff {

namespace {

// A link-creation property list that creates the intermediate groups of a path.
hid_t link_with_groups() {
  const hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
  H5Pset_create_intermediate_group(lcpl, 1);
  return lcpl;
}

void describe(hid_t ds, const std::string& unit, const std::string& description) {
  if (!unit.empty()) write_text_attribute(ds, "unit", unit);
  if (!description.empty()) write_text_attribute(ds, "description", description);
}

}  // namespace

void write_text_attribute(hid_t obj, const char* name, const std::string& text) {
  H5Id type{H5Tcopy(H5T_C_S1), H5Tclose};
  H5Tset_size(type.id, H5T_VARIABLE);
  H5Tset_cset(type.id, H5T_CSET_ASCII);
  H5Id space{H5Screate(H5S_SCALAR), H5Sclose};
  H5Id a{H5Acreate2(obj, name, type.id, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose};
  const char* p = text.c_str();
  if (a.id < 0 || H5Awrite(a.id, type.id, &p) < 0)
    throw std::runtime_error(std::string("cannot write attribute ") + name);
}

void write_vector(hid_t file, const std::string& name, const std::vector<double>& v,
                  const std::string& unit, const std::string& description) {
  const hsize_t n = v.size();
  H5Id space{H5Screate_simple(1, &n, nullptr), H5Sclose};
  const H5Id lcpl{link_with_groups(), H5Pclose};
  H5Id ds{H5Dcreate2(file, name.c_str(), H5T_NATIVE_DOUBLE, space.id, lcpl.id, H5P_DEFAULT,
                     H5P_DEFAULT),
          H5Dclose};
  if (ds.id < 0 || H5Dwrite(ds.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0)
    throw std::runtime_error("cannot write dataset " + name);
  describe(ds.id, unit, description);
}

void write_compressed_table(hid_t file, const std::string& name,
                            const std::vector<std::vector<double>>& rows, std::size_t cols,
                            const std::string& unit, const std::string& description) {
  const hsize_t dims[2] = {rows.size(), cols};
  std::vector<float> flat;
  flat.reserve(rows.size() * cols);
  for (const auto& r : rows) {
    if (r.size() != cols)
      throw std::logic_error(
          fmt::format("{}: a row of {} values in a table of {} columns", name, r.size(), cols));
    for (double x : r) flat.push_back(static_cast<float>(x));
  }
  H5Id space{H5Screate_simple(2, dims, nullptr), H5Sclose};
  H5Id dcpl{H5Pcreate(H5P_DATASET_CREATE), H5Pclose};
  // A chunk of up to 256 rows: whole rows, and an empty table still gets a valid chunk shape.
  const hsize_t chunk[2] = {std::clamp<hsize_t>(dims[0], 1, 256), std::max<hsize_t>(dims[1], 1)};
  H5Pset_chunk(dcpl.id, 2, chunk);
  H5Pset_shuffle(dcpl.id);
  H5Pset_deflate(dcpl.id, 6);
  const H5Id lcpl{link_with_groups(), H5Pclose};
  H5Id ds{H5Dcreate2(file, name.c_str(), H5T_IEEE_F32LE, space.id, lcpl.id, dcpl.id, H5P_DEFAULT),
          H5Dclose};
  if (ds.id < 0 || (!flat.empty() && H5Dwrite(ds.id, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL,
                                              H5P_DEFAULT, flat.data()) < 0))
    throw std::runtime_error("cannot write dataset " + name);
  describe(ds.id, unit, description);
}

void write_attribute(hid_t obj, const char* name, double x) {
  H5Id space{H5Screate(H5S_SCALAR), H5Sclose};
  H5Id a{H5Acreate2(obj, name, H5T_NATIVE_DOUBLE, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose};
  if (a.id < 0 || H5Awrite(a.id, H5T_NATIVE_DOUBLE, &x) < 0)
    throw std::runtime_error(std::string("cannot write attribute ") + name);
}

std::vector<double> read_dataset(const std::filesystem::path& file, const std::string& name) {
  H5Id f{H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  if (f.id < 0) throw std::runtime_error(fmt::format("cannot open {}", file.string()));
  if (H5Lexists(f.id, name.c_str(), H5P_DEFAULT) <= 0)
    throw std::runtime_error(fmt::format("{}: no dataset {}", file.string(), name));
  H5Id ds{H5Dopen2(f.id, name.c_str(), H5P_DEFAULT), H5Dclose};
  H5Id space{H5Dget_space(ds.id), H5Sclose};
  const hssize_t n = H5Sget_simple_extent_npoints(space.id);
  std::vector<double> out(static_cast<std::size_t>(std::max<hssize_t>(n, 0)));
  if (ds.id < 0 || n < 0 ||
      (n > 0 && H5Dread(ds.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0))
    throw std::runtime_error(fmt::format("{}: cannot read {}", file.string(), name));
  return out;
}

}  // namespace sheardiff
