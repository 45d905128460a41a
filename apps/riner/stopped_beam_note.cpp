#include "stopped_beam_note.hpp"

#include <cstdio>

namespace riner::app {

std::string stopped_beam_note(std::size_t readings, float floor) {
  if (readings == 0) return {};
  char read_as[320];
  if (floor > 0.0f) {
    std::snprintf(read_as, sizeof(read_as),
                  "FBP reads them, beside a metal's edge, as the largest finite reading of nine "
                  "views in ten (of their detector row in a stack), %.3g, so the metal shows, "
                  "lighter than it is and with streaks (--fill-stopped-beam interpolates them)",
                  floor);
  } else {
    std::snprintf(read_as, sizeof(read_as),
                  "FBP fills them from their neighbours, so the image shows no metal there");
  }
  return std::to_string(readings) +
         " readings of +inf (no light) look like a beam the object stopped (metal?; --json: "
         "stopped_beam_readings): " +
         read_as + "; riner reconstruct trains them as bounds";
}

}  // namespace riner::app
