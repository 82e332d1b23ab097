// A small command-line parser for the sdfstream subcommands: "--name value" options, "--flag"
// switches and positional arguments, with every problem reported as InputError(Usage).
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "gpu/context.h"

namespace sdfstream::cli {

class Args {
 public:
  // valueOptions take a value ("-o DIR", "--voxel 0.1"); flags do not ("--cpu").
  Args(int argc, char** argv, int first, const std::set<std::string>& valueOptions,
       const std::set<std::string>& flags);

  bool has(const std::string& name) const { return values_.count(name) || flags_.count(name); }
  std::optional<std::string> value(const std::string& name) const;
  double number(const std::string& name, double fallback) const;  // must be finite
  int integer(const std::string& name, int fallback, int lo, int hi) const;
  const std::vector<std::string>& positional() const { return positional_; }

 private:
  std::map<std::string, std::string> values_;
  std::set<std::string> flags_;
  std::vector<std::string> positional_;
};

// argv[first..argc) joined by spaces: the command line as the reports quote it.
std::string commandLine(int argc, char** argv, int first);

// The Vulkan device the command asked for: nullopt with --cpu (trace with the CPU reference),
// else the device named by --device (or SDFSTREAM_DEVICE, or the best one), with the Khronos
// validation layer when --validation is given (or SDFSTREAM_VALIDATION=1).
std::optional<gpu::ContextOptions> deviceFromArgs(const Args& args);
// That device opened (nullptr with --cpu).
std::unique_ptr<gpu::Context> gpuContextFromArgs(const Args& args);

}  // namespace sdfstream::cli
