#pragma once
// A and p as the calibration commands print them in JSON, and the largest difference between two
// such fits: what the CLI tests of the calibrations compare.
#include <algorithm>
#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

namespace piezoshift::testing {

struct Fit {
  double a[3][3]{};
  double p[4]{};
};

//! A and p from a JSON summary (`calibrate --json`, `fit matrix --json`).
inline Fit fit_of(const std::string& json) {
  const auto j = nlohmann::json::parse(json);
  Fit f;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      f.a[r][c] = j.at("A").at(r).at(c).get<double>();
  for (int i = 0; i < 4; ++i)
    f.p[i] = j.at("p").at(i).get<double>();
  return f;
}

//! `fit poly`'s JSON: p only (A left at 0).
inline Fit fit_of_p(const std::string& json) {
  const auto j = nlohmann::json::parse(json);
  Fit f;
  for (int i = 0; i < 4; ++i)
    f.p[i] = j.at("p").at(i).get<double>();
  return f;
}

inline double max_difference(const Fit& x, const Fit& y) {
  double d = 0.0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      d = std::max(d, std::fabs(x.a[r][c] - y.a[r][c]));
  for (int i = 0; i < 4; ++i)
    d = std::max(d, std::fabs(x.p[i] - y.p[i]));
  return d;
}

}  // namespace piezoshift::testing
