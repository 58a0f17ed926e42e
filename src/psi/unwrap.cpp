#include "piezoshift/psi/unwrap.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace piezoshift::psi {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

double wrap(double a) {
  return std::remainder(a, kTwoPi);
}

struct Edge {
  float reliability;
  std::uint32_t p;
  std::uint32_t q;
};

}  // namespace

Map unwrap_phase(const Map& wrapped, const Mask& mask) {
  if (wrapped.width != mask.width || wrapped.height != mask.height)
    throw std::invalid_argument("unwrap: phase and mask differ in size");
  const int w = wrapped.width, h = wrapped.height;
  const std::size_t n = wrapped.size();
  std::vector<std::uint8_t> in(n, 0);
  for (std::size_t p = 0; p < n; ++p)
    in[p] = mask.v[p] && std::isfinite(wrapped.v[p]) ? 1 : 0;
  auto idx = [w](int i, int j) { return static_cast<std::size_t>(j) * w + i; };

  // pixel reliabilities
  std::vector<float> rel(n, 0.0f);
  for (int j = 1; j + 1 < h; ++j)
    for (int i = 1; i + 1 < w; ++i) {
      const std::size_t p = idx(i, j);
      if (!in[p])
        continue;
      bool full = true;
      for (int dj = -1; dj <= 1 && full; ++dj)
        for (int di = -1; di <= 1; ++di)
          if (!in[idx(i + di, j + dj)]) {
            full = false;
            break;
          }
      if (!full)
        continue;
      const double c = wrapped.v[p];
      auto second = [&](int di, int dj) {
        return wrap(wrapped.v[idx(i - di, j - dj)] - c) - wrap(c - wrapped.v[idx(i + di, j + dj)]);
      };
      const double H = second(1, 0), V = second(0, 1), D1 = second(1, 1), D2 = second(1, -1);
      const double D = std::sqrt(H * H + V * V + D1 * D1 + D2 * D2);
      rel[p] = static_cast<float>(1.0 / std::max(D, 1e-12));
    }

  std::vector<Edge> edges;
  edges.reserve(2 * n);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const std::size_t p = idx(i, j);
      if (!in[p])
        continue;
      if (i + 1 < w && in[p + 1])
        edges.push_back({rel[p] + rel[p + 1], static_cast<std::uint32_t>(p),
                         static_cast<std::uint32_t>(p + 1)});
      if (j + 1 < h && in[p + static_cast<std::size_t>(w)])
        edges.push_back({rel[p] + rel[p + static_cast<std::size_t>(w)],
                         static_cast<std::uint32_t>(p),
                         static_cast<std::uint32_t>(p + static_cast<std::size_t>(w))});
    }
  std::sort(edges.begin(), edges.end(),
            [](const Edge& a, const Edge& b) { return a.reliability > b.reliability; });

  // groups as linked lists: head of each pixel's group, next member, tail and size of each head
  Map out(w, h, std::nan(""));
  std::vector<std::uint32_t> head(n), next(n, UINT32_MAX), tail(n), size(n, 1);
  for (std::size_t p = 0; p < n; ++p) {
    head[p] = static_cast<std::uint32_t>(p);
    tail[p] = static_cast<std::uint32_t>(p);
    if (in[p])
      out.v[p] = wrapped.v[p];
  }
  for (const Edge& e : edges) {
    std::uint32_t a = head[e.p], b = head[e.q];
    if (a == b)
      continue;
    // shift the smaller group so that the edge's difference is its wrapped value
    std::uint32_t from = e.q, to = e.p;
    if (size[a] < size[b]) {
      std::swap(a, b);
      std::swap(from, to);
    }
    const double k = std::round((out.v[to] - out.v[from]) / kTwoPi);
    const double shift = k * kTwoPi;
    for (std::uint32_t m = b; m != UINT32_MAX; m = next[m]) {
      out.v[m] += shift;
      head[m] = a;
    }
    next[tail[a]] = b;
    tail[a] = tail[b];
    size[a] += size[b];
  }
  return out;
}

}  // namespace piezoshift::psi
