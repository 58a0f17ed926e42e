#pragma once
// Images as numpy arrays, shared by the camera and instrument bindings (docs/python.md): a
// frame's counts as (height, width) uint16, a map as (height, width) float64 (NaN where it has no
// value), a mask as (height, width) bool. All are copies.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstdint>
#include <string>

#include "piezoshift/camera/frame.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/psi/grid.hpp"

namespace piezoshift::python {

namespace py = pybind11;

inline py::array_t<std::uint16_t> counts_to_numpy(const camera::Frame& f) {
  py::array_t<std::uint16_t> a(
      {static_cast<py::ssize_t>(f.height_px), static_cast<py::ssize_t>(f.width_px)});
  std::copy(f.counts.begin(), f.counts.end(), a.mutable_data());
  return a;
}

inline py::array_t<double> map_to_numpy(const psi::Map& m) {
  py::array_t<double> a({static_cast<py::ssize_t>(m.height), static_cast<py::ssize_t>(m.width)});
  std::copy(m.v.begin(), m.v.end(), a.mutable_data());
  return a;
}

inline py::array_t<bool> mask_to_numpy(const psi::Mask& m) {
  py::array_t<bool> a({static_cast<py::ssize_t>(m.height), static_cast<py::ssize_t>(m.width)});
  bool* out = a.mutable_data();
  for (std::size_t p = 0; p < m.v.size(); ++p)
    out[p] = m.v[p] != 0;
  return a;
}

//! A (height, width) array of any dtype, nonzero inside; name is the argument's, for messages.
inline psi::Mask mask_from_numpy(const py::object& o, int width_px, int height_px,
                                 const char* name) {
  using In = py::array_t<double, py::array::c_style | py::array::forcecast>;
  const In a = o.cast<In>();
  if (a.ndim() != 2 || a.shape(0) != height_px || a.shape(1) != width_px)
    throw core::InputError(std::string(name) + ": expected a (" + std::to_string(height_px) + ", " +
                           std::to_string(width_px) + ") array, the frames' size");
  psi::Mask mask(width_px, height_px, 0);
  for (std::size_t p = 0; p < mask.v.size(); ++p)
    mask.v[p] = a.data()[p] != 0.0 ? 1 : 0;
  return mask;
}

}  // namespace piezoshift::python
