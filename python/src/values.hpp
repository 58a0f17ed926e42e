#pragma once
// What every binding file shares: numpy copies of Vec3, Mat3 and series, their conversions back,
// and the field helpers (docs/python.md: value structs keep the C++ field names; Vec3 and Mat3
// come back as numpy copies and are set whole; series are 1-D numpy arrays).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "piezoshift/control/vec3.hpp"
#include "piezoshift/core/input_error.hpp"

namespace piezoshift::python {

namespace py = pybind11;
namespace ps = piezoshift;
using ps::control::Mat3;
using ps::control::Vec3;

using Array = py::array_t<double>;
// What functions taking data accept: any sequence numpy converts, copied to contiguous doubles.
using InArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

inline Array to_numpy(const std::vector<double>& v) {
  Array a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

inline Array to_numpy(const Vec3& v) {
  Array a(3);
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

inline Array to_numpy(const Mat3& m) {
  Array a({3, 3});
  auto r = a.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < 3; ++i) {
    for (py::ssize_t j = 0; j < 3; ++j)
      r(i, j) = m[i][j];
  }
  return a;
}

// n x 3 numpy array of a vector of Vec3.
inline Array to_numpy(const std::vector<Vec3>& rows) {
  Array a({static_cast<py::ssize_t>(rows.size()), py::ssize_t{3}});
  auto r = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    for (py::ssize_t j = 0; j < 3; ++j)
      r(static_cast<py::ssize_t>(i), j) = rows[i][j];
  }
  return a;
}

// A 1-D float array from anything numpy can convert (lists, arrays of any dtype).
inline std::vector<double> from_numpy_1d(const InArray& a, const char* name) {
  if (a.ndim() != 1)
    throw ps::core::InputError(std::string(name) + ": expected a 1-D array");
  return {a.data(), a.data() + a.size()};
}

// An n x 3 array (rows P1..P3 or S1..S3) into Vec3 rows.
inline std::vector<Vec3> from_numpy_n3(const InArray& a, const char* name) {
  if (a.ndim() != 2 || a.shape(1) != 3) {
    throw ps::core::InputError(std::string(name) + ": expected an n x 3 array");
  }
  std::vector<Vec3> rows(static_cast<std::size_t>(a.shape(0)));
  auto r = a.unchecked<2>();
  for (py::ssize_t i = 0; i < a.shape(0); ++i) {
    for (py::ssize_t j = 0; j < 3; ++j)
      rows[static_cast<std::size_t>(i)][j] = r(i, j);
  }
  return rows;
}

//! A library encoder's JSON as Python objects, through Python's json module, so the dict holds
//! exactly what the CLI's --json prints (NaN and infinity are null in both).
inline py::object json_to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

}  // namespace piezoshift::python

// Field helpers: plain numbers and nested structs, Vec3/Mat3 as numpy copies, series as numpy.
#define PS_RW(T, f) def_readwrite(#f, &T::f)
#define PS_RO(T, f) def_readonly(#f, &T::f)
#define PS_V3(T, f)                                 \
  def_property(                                     \
      #f, [](const T& s) { return to_numpy(s.f); }, \
      [](T& s, const decltype(T::f)& v) { s.f = v; })
#define PS_SERIES(T, f)                             \
  def_property(                                     \
      #f, [](const T& s) { return to_numpy(s.f); }, \
      [](T& s, const decltype(T::f)& v) { s.f = v; })
