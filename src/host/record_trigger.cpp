#include "piezoshift/host/record_trigger.hpp"

namespace piezoshift::host {

void RecordTrigger::set_source(int source, std::uint64_t sequence) {
  source_ = source;
  if (source_ == 4)
    restart(sequence);
}

void RecordTrigger::motion(std::uint64_t sequence) {
  if (source_ <= 1)
    restart(sequence);
}

void RecordTrigger::line_done(std::string_view name, std::uint64_t sequence) {
  if (source_ == 2 && name != "DRT") {
    restart(sequence);
    source_ = 0;
  }
}

void RecordTrigger::restart(std::uint64_t sequence) {
  recorder_.restart();
  from_sequence_ = sequence;
}

}  // namespace piezoshift::host
