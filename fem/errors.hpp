#pragma once
// Errors in three tiers (style.md): debug asserts for invariants, InputError for bad user input
// (names the file, the key, the value and the allowed range), NumericalError for physical failure
// (names the element or node and where it is).
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <petscsys.h>

namespace ncfsim {

/// Allowed interval of a number; bounds are inclusive unless marked open.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;
  static Range positive() { return {0, std::numeric_limits<double>::infinity(), true, false}; }
  static Range non_negative() { return {0, std::numeric_limits<double>::infinity(), false, false}; }
  static Range closed(double a, double b) { return {a, b, false, false}; }
  static Range open(double a, double b) { return {a, b, true, true}; }
  static Range open_closed(double a, double b) { return {a, b, true, false}; }
  bool contains(double v) const {
    if (!std::isfinite(v)) return false;
    if (lo_open ? !(v > lo) : !(v >= lo)) return false;
    return hi_open ? v < hi : v <= hi;
  }
  /// "[0, 10]", "> 0", ">= 0", "finite".
  std::string describe() const {
    std::ostringstream os;
    os.precision(6);
    const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
    if (has_lo && has_hi)
      os << (lo_open ? "(" : "[") << lo << ", " << hi << (hi_open ? ")" : "]");
    else if (has_lo)
      os << (lo_open ? "> " : ">= ") << lo;
    else if (has_hi)
      os << (hi_open ? "< " : "<= ") << hi;
    else
      os << "finite";
    return os.str();
  }
};

/// Bad user input: names the file, the key path (`contact[0].pair[1].friction`) and, where known,
/// the value as given and what is allowed (a range or a list of choices).
class InputError : public std::runtime_error {
 public:
  InputError(std::string file, std::string key, const std::string& message, std::string value = {},
             std::string allowed = {})
      : std::runtime_error(format(file, key, message)),
        message_(message),
        file_(std::move(file)),
        key_(std::move(key)),
        value_(std::move(value)),
        allowed_(std::move(allowed)) {}
  /// "value 12 out of range, allowed [0, 10]" (`entry` >= 0: "entry 2 = 12 out of range, ...").
  static InputError out_of_range(std::string file, std::string key, double value, const Range& range,
                                 long entry = -1) {
    std::ostringstream v, os;
    v << value;
    if (entry >= 0) os << "entry " << entry << " = ";
    else os << "value ";
    os << v.str() << " out of range, allowed " << range.describe();
    return {std::move(file), std::move(key), os.str(), v.str(), range.describe()};
  }
  /// "'x' is not allowed; one of 'a', 'b'".
  static InputError not_one_of(std::string file, std::string key, const std::string& value,
                               const std::vector<std::string>& choices) {
    std::string all;
    for (const auto& c : choices) all += (all.empty() ? "" : ", ") + ("'" + c + "'");
    return {std::move(file), std::move(key), "'" + value + "' is not allowed; one of " + all, value, all};
  }
  const std::string& file() const { return file_; }
  const std::string& key() const { return key_; }
  const std::string& value() const { return value_; }      // "" when not known
  const std::string& allowed() const { return allowed_; }  // "" when not known
  const std::string& message() const { return message_; }  // without the file and key

 private:
  static std::string format(const std::string& file, const std::string& key,
                            const std::string& message) {
    std::string s;
    if (!file.empty()) s += file + ": ";
    if (!key.empty()) s += "key '" + key + "': ";
    return s + message;
  }
  std::string message_, file_, key_, value_, allowed_;
};

/// The one range check of a value that does not come through the case reader's typed getters
/// (a module's validate()): throws InputError::out_of_range.
inline void check_range(const std::string& file, const std::string& key, double value, const Range& range) {
  if (!range.contains(value)) throw InputError::out_of_range(file, key, value, range);
}

/// Instability, negative volume, energy balance past its limit: exit code 3.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws on a PETSc error code, naming the call.
inline void petsc_check(PetscErrorCode ierr, const char* call, const char* file, int line) {
  if (ierr != 0) {
    const char* text = nullptr;
    PetscErrorMessage(ierr, &text, nullptr);
    throw std::runtime_error(std::string("PETSc error in ") + call + " (" + file + ":" +
                             std::to_string(line) + "): " + (text ? text : "unknown"));
  }
}

}  // namespace ncfsim

#define NCF_PETSC(call) ::ncfsim::petsc_check((call), #call, __FILE__, __LINE__)
