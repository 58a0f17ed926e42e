#pragma once
// `piezoshift psi compare A.gsf B.gsf [--out DIR] [--json]` (docs/psi.md): the difference B - A,
// its RMS, and the Zernike terms of A, B and the difference over the pixels valid in both.
#include <string>

namespace piezoshift::app {

struct PsiCompareOptions {
  std::string a;
  std::string b;
  std::string out;  //!< "" none; else difference_m.gsf and comparison.json go there
  bool json = false;
};

//! 0 when compared; core::InputError (exit 2) for an unreadable file, naming it, or maps whose
//! sizes or lateral scales differ, saying which.
int run_psi_compare(const PsiCompareOptions& o);

}  // namespace piezoshift::app
