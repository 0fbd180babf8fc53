#include "whitted/whitted.h"

namespace whitted {

const char* version() { return WHITTED_VERSION; }

}  // namespace whitted
