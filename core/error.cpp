#include "core/error.h"

namespace sdfstream {

const char* toString(InputErrorKind kind) {
  switch (kind) {
    case InputErrorKind::Io: return "io";
    case InputErrorKind::Malformed: return "malformed";
    case InputErrorKind::MissingData: return "missing-data";
    case InputErrorKind::OutOfRange: return "out-of-range";
    case InputErrorKind::NonFinite: return "non-finite";
    case InputErrorKind::Empty: return "empty";
    case InputErrorKind::NotLevelSet: return "not-level-set";
    case InputErrorKind::Truncated: return "truncated";
    case InputErrorKind::TooLarge: return "too-large";
    case InputErrorKind::Checksum: return "checksum";
    case InputErrorKind::Version: return "version";
    case InputErrorKind::Usage: return "usage";
    case InputErrorKind::Unsupported: return "unsupported";
  }
  return "unknown";
}

}  // namespace sdfstream
