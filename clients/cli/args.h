// Shared pieces of the command-line subcommands: checked number parsing and
// the --help / usage-error / run sequence every subcommand follows.
#pragma once

#include <functional>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace hj::cli {

// A finite number; std::invalid_argument naming the flag otherwise.
double parse_number(const std::string& flag, const std::string& text);
// A whole number in [lo, hi]; std::invalid_argument naming the flag otherwise.
int parse_int(const std::string& flag, const std::string& text, int lo, int hi);

// Walks a subcommand's arguments: for (ArgCursor c(args); c.next();) reads
// c.arg(), and c.value() takes the one after an option or names the option
// that lacks it.
class ArgCursor {
 public:
  explicit ArgCursor(const std::vector<std::string>& args) : args_(args) {}
  bool next() { return ++i_ < args_.size(); }
  const std::string& arg() const { return args_[i_]; }
  const std::string& value() {
    if (i_ + 1 >= args_.size()) throw std::invalid_argument(arg() + " needs a value");
    return args_[++i_];
  }

 private:
  const std::vector<std::string>& args_;
  size_t i_ = static_cast<size_t>(-1);
};

// Prints usage for --help (exit 0); runs parse then run, turning its
// std::invalid_argument from parsing into a usage error (exit 2). parse
// must throw only on bad arguments; run's own errors propagate.
template <class Args>
int run_subcommand(const std::string& name, const char* usage, const std::vector<std::string>& args,
                   const std::function<Args(const std::vector<std::string>&)>& parse,
                   const std::function<int(const Args&)>& run) {
  for (const auto& a : args)
    if (a == "--help" || a == "-h") {
      std::cout << usage;
      return 0;
    }
  Args parsed;
  try {
    parsed = parse(args);
  } catch (const std::invalid_argument& e) {
    std::cerr << "hapticjam " << name << ": " << e.what() << "\n" << usage;
    return 2;
  }
  return run(parsed);
}

}  // namespace hj::cli
