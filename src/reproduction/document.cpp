#include "piezoshift/reproduction/document.hpp"

#include <fstream>
#include <system_error>
#include <utility>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::reproduction {
namespace {

std::string html_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace

void Document::heading(int level, std::string text) {
  blocks.push_back({Block::kHeading, level, std::move(text), {}, {}});
}

void Document::paragraph(std::string text) {
  blocks.push_back({Block::kParagraph, 0, std::move(text), {}, {}});
}

void Document::code(std::string text) {
  blocks.push_back({Block::kCode, 0, std::move(text), {}, {}});
}

void Document::table(std::vector<std::vector<std::string>> rows) {
  blocks.push_back({Block::kTable, 0, {}, std::move(rows), {}});
}

void Document::image(std::string caption, std::string path) {
  blocks.push_back({Block::kImage, 0, std::move(caption), {}, std::move(path)});
}

std::string to_markdown(const std::vector<Block>& blocks) {
  std::string out;
  for (const Block& b : blocks) {
    switch (b.kind) {
      case Block::kHeading:
        out += std::string(b.level, '#') + " " + b.text + "\n\n";
        break;
      case Block::kParagraph:
        out += b.text + "\n\n";
        break;
      case Block::kCode:
        out += "```\n" + b.text + "\n```\n\n";
        break;
      case Block::kImage:
        out += "![" + b.text + "](" + b.path + ")\n\n";
        break;
      case Block::kTable:
        for (std::size_t r = 0; r < b.rows.size(); ++r) {
          out += "|";
          for (const auto& cell : b.rows[r])
            out += " " + cell + " |";
          out += "\n";
          if (r == 0) {
            out += "|";
            for (std::size_t c = 0; c < b.rows[r].size(); ++c)
              out += "---|";
            out += "\n";
          }
        }
        out += "\n";
        break;
    }
  }
  return out;
}

std::string to_html(const std::vector<Block>& blocks, const std::string& title) {
  std::string out = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" +
                    html_escape(title) +
                    "</title>\n<style>body{font-family:sans-serif;max-width:60em;margin:2em auto;"
                    "line-height:1.4}table{border-collapse:collapse;margin:1em 0}td,th{border:1px "
                    "solid #999;padding:.3em .6em;text-align:left}img{max-width:100%}"
                    "pre{background:#f4f4f4;padding:.5em}</style>\n</head><body>\n";
  for (const Block& b : blocks) {
    switch (b.kind) {
      case Block::kHeading:
        out += fmt::format("<h{0}>{1}</h{0}>\n", b.level, html_escape(b.text));
        break;
      case Block::kParagraph:
        out += "<p>" + html_escape(b.text) + "</p>\n";
        break;
      case Block::kCode:
        out += "<pre>" + html_escape(b.text) + "</pre>\n";
        break;
      case Block::kImage:
        out += "<figure><img src=\"" + html_escape(b.path) + "\" alt=\"" + html_escape(b.text) +
               "\"><figcaption>" + html_escape(b.text) + "</figcaption></figure>\n";
        break;
      case Block::kTable:
        out += "<table>\n";
        for (std::size_t r = 0; r < b.rows.size(); ++r) {
          out += "<tr>";
          for (const auto& cell : b.rows[r]) {
            out += (r == 0 ? "<th>" : "<td>") + html_escape(cell) + (r == 0 ? "</th>" : "</td>");
          }
          out += "</tr>\n";
        }
        out += "</table>\n";
        break;
    }
  }
  return out + "</body></html>\n";
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream f(path);
  f << text;
  f.close();
  if (!f)
    throw core::InputError(fmt::format("{}: cannot write", path.string()));
}

void create_report_folder(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec)
    throw core::InputError(
        fmt::format("{}: cannot create the folder: {}", dir.string(), ec.message()));
}

}  // namespace piezoshift::reproduction
