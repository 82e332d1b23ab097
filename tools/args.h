// A small command-line parser for the sdfstream subcommands: "--name value" options, "--flag"
// switches and positional arguments, with every problem reported as InputError(Usage).
#pragma once

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

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

}  // namespace sdfstream::cli
