#include "core/error.h"
#include "tools/commands.h"

namespace sdfstream::cli {
int runVerify(int, char**) { throw InputError(InputErrorKind::Usage, "verify", "not implemented yet"); }
int runMerge(int, char**) { throw InputError(InputErrorKind::Usage, "merge", "not implemented yet"); }
}  // namespace sdfstream::cli
