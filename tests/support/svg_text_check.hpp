#pragma once
// Checks on the text of a figure as gnuplot's svg terminal writes it (docs/figures.md): no two
// pieces of text overlap, every axis label carries a unit, and no unit is spelt in ASCII ("um",
// "+-", "lambda") where the symbol belongs.
//
// gnuplot writes each piece of text as
//   <g transform="translate(X,Y) [rotate(A)]" ... font-size="S" text-anchor="start|middle|end">
//     <text>...</text>
// with (X, Y) on the text's baseline at its anchor. No font metrics are at hand, so each box is
// estimated: its width is kCharWidthEm x S per character (a code point; 0.55 em is DejaVu Sans's
// mean advance over mixed lower-case text, digits and spaces; capitals run wider, narrow
// glyphs such as "1", "i", "." narrower), its height S, from 0.75 S above the baseline (the
// ascent of capitals and digits) to 0.2 S below (descenders). Rotated text (y labels,
// rotate(+-90)) swaps width and height. A boxed label's background copy (drawn through the
// textbox filter) is skipped. Two boxes overlap when they share more than kSlackPx in
// both directions, so text that merely touches (tick labels of a dense axis) is not flagged.
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

namespace piezoshift::testing {

inline constexpr double kCharWidthEm = 0.55;
inline constexpr double kSlackPx = 0.5;

struct SvgText {
  std::string text;
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // estimated box, SVG user units
};

// Code points of UTF-8 text with XML entities (&amp; &#177; ...) counted as one character each.
inline std::size_t glyph_count(const std::string& s) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c == '&') {
      const auto semi = s.find(';', i);
      if (semi != std::string::npos && semi - i < 10)
        i = semi;
      ++n;
    } else if ((c & 0xC0) != 0x80) {
      ++n;
    }
  }
  return n;
}

inline std::string attribute(const std::string& tag, const std::string& name) {
  const std::string key = name + "=\"";
  const auto at = tag.find(key);
  if (at == std::string::npos)
    return {};
  const auto end = tag.find('"', at + key.size());
  return tag.substr(at + key.size(), end - at - key.size());
}

// Every non-blank <text> of the SVG with its estimated box.
inline std::vector<SvgText> svg_texts(const std::string& svg) {
  std::vector<SvgText> out;
  std::size_t pos = 0;
  while ((pos = svg.find("<g transform=\"translate(", pos)) != std::string::npos) {
    const auto tag_end = svg.find('>', pos);
    const std::string tag = svg.substr(pos, tag_end - pos);
    pos = tag_end;
    // A boxed label is written twice: first through the textbox filter (its opaque background),
    // then as itself; the background copy is not a second text.
    if (tag.find("filter:url(") != std::string::npos)
      continue;
    const auto text_at = svg.find("<text", tag_end);
    const auto next_g = svg.find("<g", tag_end);
    if (text_at == std::string::npos || (next_g != std::string::npos && next_g < text_at))
      continue;
    const auto open_end = svg.find('>', text_at);
    const auto close = svg.find("</text>", open_end);
    std::string raw = svg.substr(open_end + 1, close - open_end - 1);
    std::string text;  // without markup (tspan)
    for (std::size_t i = 0; i < raw.size(); ++i) {
      if (raw[i] == '<')
        i = raw.find('>', i);
      else
        text += raw[i];
    }
    const auto first = text.find_first_not_of(' ');
    if (first == std::string::npos)
      continue;
    text = text.substr(first, text.find_last_not_of(' ') - first + 1);
    double x = 0, y = 0, angle = 0;
    const std::string transform = attribute(tag, "transform");
    std::sscanf(transform.c_str(), "translate(%lf,%lf) rotate(%lf)", &x, &y, &angle);
    const std::string size_attr = attribute(tag, "font-size");
    const double size = size_attr.empty() ? 10.0 : std::stod(size_attr);
    const std::string anchor = attribute(tag, "text-anchor");
    const double w = kCharWidthEm * size * static_cast<double>(glyph_count(text));
    // Along the text: where it starts relative to the anchor; across: ascent and descent.
    const double along0 = anchor == "end" ? -w : anchor == "middle" ? -w / 2 : 0.0;
    const double a0 = along0, a1 = along0 + w, c0 = -0.75 * size, c1 = 0.2 * size;
    SvgText t{text, x + a0, y + c0, x + a1, y + c1};
    if (std::abs(std::abs(angle) - 90.0) < 1.0 || std::abs(angle - 270.0) < 1.0) {
      // rotate(270) or rotate(-90): the text runs upwards; its "across" goes to the right.
      const bool up = angle > 180.0 || angle < 0.0;
      t = up ? SvgText{text, x + c0, y - a1, x + c1, y - a0}
             : SvgText{text, x - c1, y + a0, x - c0, y + a1};
    }
    out.push_back(t);
  }
  return out;
}

// "a" / "b" for every pair of texts whose boxes overlap.
inline std::vector<std::string> overlapping_texts(const std::vector<SvgText>& texts) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < texts.size(); ++i) {
    for (std::size_t j = i + 1; j < texts.size(); ++j) {
      const SvgText& a = texts[i];
      const SvgText& b = texts[j];
      const double dx = std::min(a.x1, b.x1) - std::max(a.x0, b.x0);
      const double dy = std::min(a.y1, b.y1) - std::max(a.y0, b.y0);
      if (dx > kSlackPx && dy > kSlackPx)
        out.push_back(fmt::format("'{}' at ({:.0f}, {:.0f}) / '{}' at ({:.0f}, {:.0f})", a.text,
                                  a.x0, a.y0, b.text, b.x0, b.y0));
    }
  }
  return out;
}

// The axis labels a gnuplot script sets: `set xlabel '...'`, ylabel, y2label, cblabel; the
// empty ones (an axis without label) left out. Quotes are gnuplot's single-quoted strings.
inline std::vector<std::string> script_axis_labels(const std::string& gp) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  while ((pos = gp.find("\nset ", pos)) != std::string::npos) {
    pos += 5;
    const auto space = gp.find(' ', pos);
    const std::string what = gp.substr(pos, space - pos);
    if (what != "xlabel" && what != "ylabel" && what != "y2label" && what != "cblabel")
      continue;
    if (gp[space + 1] != '\'')
      continue;
    std::string label;
    for (std::size_t i = space + 2; i < gp.size(); ++i) {
      if (gp[i] == '\'' && i + 1 < gp.size() && gp[i + 1] == '\'')
        label += '\'', ++i;
      else if (gp[i] == '\'')
        break;
      else
        label += gp[i];
    }
    if (!label.empty())
      out.push_back(label);
  }
  return out;
}

// A unit in brackets ("time [s]", "|L| [dB]"), or a count, whose unit is one and is named by the
// label's word for what is counted.
inline bool has_unit(const std::string& label) {
  const auto open = label.rfind('[');
  const auto close = label.rfind(']');
  if (open != std::string::npos && close != std::string::npos && close > open + 1)
    return true;
  for (const char* counted : {"count", "index", "frame number", "exposure number"}) {
    if (label.find(counted) != std::string::npos)
      return true;
  }
  return false;
}

// Units spelt in ASCII where the figure should carry the symbol.
inline std::vector<std::string> ascii_units(const std::vector<SvgText>& texts) {
  std::vector<std::string> out;
  for (const SvgText& t : texts) {
    const std::string& s = t.text;
    const bool um = s.find(" um") != std::string::npos || s.find("[um]") != std::string::npos ||
                    s.find("(um") != std::string::npos || s.find("_um") != std::string::npos;
    if (um || s.find("+-") != std::string::npos || s.find("lambda") != std::string::npos ||
        s.find("sigma") != std::string::npos || s.find("[deg]") != std::string::npos)
      out.push_back(s);
  }
  return out;
}

inline std::string read_whole_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Everything wrong with the text of one figure: <stem>.svg, checked against the axis labels of
// the <stem>.gp beside it. Empty when the figure is fine.
inline std::vector<std::string> figure_text_problems(const std::filesystem::path& svg_path) {
  std::vector<std::string> out;
  const std::string svg = read_whole_file(svg_path);
  const std::string name = svg_path.filename().string();
  if (svg.rfind("<?xml", 0) != 0 || svg.find("</svg>") == std::string::npos)
    return {name + ": not a whole SVG document"};
  const std::vector<SvgText> texts = svg_texts(svg);
  if (texts.empty())
    out.push_back(name + ": no text found");
  for (const std::string& o : overlapping_texts(texts))
    out.push_back(name + ": text overlaps: " + o);
  for (const std::string& a : ascii_units(texts))
    out.push_back(name + ": unit in ASCII: '" + a + "'");
  std::filesystem::path gp = svg_path;
  gp.replace_extension(".gp");
  const std::vector<std::string> labels = script_axis_labels(read_whole_file(gp));
  if (labels.empty())
    out.push_back(name + ": no axis label in " + gp.filename().string());
  for (const std::string& l : labels) {
    if (!has_unit(l))
      out.push_back(name + ": axis label without unit: '" + l + "'");
  }
  return out;
}

// figure_text_problems of every SVG in a folder (not its subfolders), with how many were read.
inline std::vector<std::string> folder_figure_problems(const std::filesystem::path& dir,
                                                       int& figures) {
  std::vector<std::string> out;
  figures = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().extension() != ".svg")
      continue;
    ++figures;
    for (std::string& p : figure_text_problems(e.path()))
      out.push_back(std::move(p));
  }
  return out;
}

}  // namespace piezoshift::testing
