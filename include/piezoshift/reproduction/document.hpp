#pragma once
// A report as a list of blocks rendered twice, as Markdown and as HTML, so both say the same
// (`reproduce`'s report.md / report.html, `compare`'s comparison.md / comparison.html).
#include <filesystem>
#include <string>
#include <vector>

namespace piezoshift::reproduction {

struct Block {
  enum Kind { kHeading, kParagraph, kTable, kImage, kCode } kind;
  int level = 0;
  std::string text;                            //!< heading, paragraph, code, image caption
  std::vector<std::vector<std::string>> rows;  //!< table: first row is the header
  std::string path;                            //!< image, relative to the document
};

//! A report's blocks appended in reading order, one call per block, so a report writer reads as
//! its outline.
struct Document {
  std::vector<Block> blocks;

  void heading(int level, std::string text);
  void paragraph(std::string text);
  void code(std::string text);
  void table(std::vector<std::vector<std::string>> rows);
  void image(std::string caption, std::string path);
};

std::string to_markdown(const std::vector<Block>& blocks);
//! A standalone page; text is escaped.
std::string to_html(const std::vector<Block>& blocks, const std::string& title);
//! Throws core::InputError naming the path when it cannot be written.
void write_text(const std::filesystem::path& path, const std::string& text);
//! Creates dir and its parents; throws core::InputError naming it when that fails.
void create_report_folder(const std::filesystem::path& dir);

}  // namespace piezoshift::reproduction
