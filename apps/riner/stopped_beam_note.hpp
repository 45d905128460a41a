// What `riner fbp` says of readings of +inf kept as a beam the object stopped: one sentence for
// the command line's note and, through python_wording, Python's warning.
#pragma once

#include <cstddef>
#include <string>

namespace riner::app {

// The sentence for `readings` such readings read at `floor` (0: filled from their neighbours);
// empty where there are none.
std::string stopped_beam_note(std::size_t readings, float floor);

}  // namespace riner::app
