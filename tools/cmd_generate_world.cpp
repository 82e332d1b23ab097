#include "core/error.h"
#include "tools/commands.h"

namespace sdfstream::cli {
int runGenerateWorld(int, char**) {
  throw InputError(InputErrorKind::Usage, "generate-world", "not implemented yet");
}
}  // namespace sdfstream::cli
