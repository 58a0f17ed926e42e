#pragma once
// A progress bar on stderr for long jobs, drawn only when stderr is a terminal (so logs and CI
// output stay clean): "  [3/8] linearity        [#########           ]  45 %".
#include <string>
#include <string_view>

#include "piezoshift/rig/progress.hpp"

namespace piezoshift::app {

class ProgressBar {
 public:
  explicit ProgressBar(int stages);
  ~ProgressBar();
  //! done/total of the stage called label; a new label starts the next stage.
  void update(double done, double total, std::string_view label);
  //! update() as the Progress callback that long jobs take.
  rig::Progress callback() {
    return
        [this](double done, double total, std::string_view label) { update(done, total, label); };
  }

 private:
  bool enabled_;
  int stages_;
  int stage_ = 0;
  std::string label_;
  int last_percent_ = -1;
};

}  // namespace piezoshift::app
