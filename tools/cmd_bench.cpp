#include "core/error.h"
#include "tools/commands.h"

namespace sdfstream::cli {
int runBench(int, char**) { throw InputError(InputErrorKind::Usage, "bench", "not implemented yet"); }
}  // namespace sdfstream::cli
