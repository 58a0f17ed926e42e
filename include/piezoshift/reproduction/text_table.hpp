#pragma once
// A table for the terminal (`compare`'s and `reproduce`'s summaries): every column as wide as its
// widest cell, counted in characters (UTF-8 code points, so "µm" and "±" count one each), the
// first column left-aligned and the others right-aligned, a rule under the header. Long rows
// widen their column instead of breaking it.
#include <string>
#include <vector>

namespace piezoshift::reproduction {

//! rows[0] is the header; each line starts with indent spaces and ends with '\n'. Rows may have
//! fewer cells than the header (the rest is blank).
std::string text_table(const std::vector<std::vector<std::string>>& rows, int indent = 2);

//! Characters in a UTF-8 string (its code points).
std::size_t display_width(const std::string& s);

}  // namespace piezoshift::reproduction
