#include "tools/args.h"

#include <cmath>
#include <cstdlib>

#include "core/error.h"
#include "gpu/context.h"

namespace sdfstream::cli {
namespace {
[[noreturn]] void usage(const std::string& what) {
  throw InputError(InputErrorKind::Usage, "command line", what);
}
}  // namespace

Args::Args(int argc, char** argv, int first, const std::set<std::string>& valueOptions,
           const std::set<std::string>& flags) {
  for (int i = first; i < argc; ++i) {
    std::string a = argv[i];
    if (a.size() > 1 && a[0] == '-' && !(a.size() > 1 && (std::isdigit(a[1]) || a[1] == '.'))) {
      if (flags.count(a)) {
        flags_.insert(a);
      } else if (valueOptions.count(a)) {
        if (i + 1 >= argc) usage(a + " needs a value");
        values_[a] = argv[++i];
      } else {
        usage("unknown option " + a + " (see --help)");
      }
    } else {
      positional_.push_back(a);
    }
  }
}

std::optional<std::string> Args::value(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

double Args::number(const std::string& name, double fallback) const {
  auto v = value(name);
  if (!v) return fallback;
  char* end = nullptr;
  double d = std::strtod(v->c_str(), &end);
  if (v->empty() || *end != '\0' || !std::isfinite(d))
    usage(name + " expects a number, got '" + *v + "'");
  return d;
}

int Args::integer(const std::string& name, int fallback, int lo, int hi) const {
  auto v = value(name);
  if (!v) return fallback;
  char* end = nullptr;
  long n = std::strtol(v->c_str(), &end, 10);
  if (v->empty() || *end != '\0' || n < lo || n > hi)
    usage(name + " expects an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
          "], got '" + *v + "'");
  return int(n);
}

std::string commandLine(int argc, char** argv, int first) {
  std::string line;
  for (int i = first; i < argc; ++i) {
    if (i > first) line += ' ';
    line += argv[i];
  }
  return line;
}

std::optional<gpu::ContextOptions> deviceFromArgs(const Args& args) {
  if (args.has("--cpu")) return std::nullopt;
  gpu::ContextOptions options;
  options.device = args.value("--device").value_or("");
  options.validation = args.has("--validation");
  return options;
}

std::unique_ptr<gpu::Context> gpuContextFromArgs(const Args& args) {
  const auto device = deviceFromArgs(args);
  return device ? gpu::Context::create(*device) : nullptr;
}

}  // namespace sdfstream::cli
