#pragma once
// The dashboard's single page (docs/dashboard.md), built from web/dashboard by its npm build and
// compiled in (dashboard_page.cpp is generated in the build folder), so `serve` needs no files.
#include <string_view>

namespace piezoshift::app {

//! The whole HTML page, scripts and styles inlined.
std::string_view dashboard_page();

}  // namespace piezoshift::app
