// The library's messages name the command line's options (--offset-px, --flat, ...): in Python
// the same message names the keyword argument that does the same (center=, flat=, ...).
#pragma once

#include <string>

namespace riner::python {

// MESSAGE with each command-line option it names replaced by its Python keyword.
std::string python_wording(std::string message);

}  // namespace riner::python
