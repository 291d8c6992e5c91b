#pragma once
// Errors in three tiers (style.md): debug asserts for invariants, InputError for bad user input
// (names the file, the key, the value and the allowed range), NumericalError for physical failure
// (names the element or node and where it is).
#include <array>
#include <cassert>
#include <stdexcept>
#include <string>

#include <petscsys.h>

namespace ncfsim {

class InputError : public std::runtime_error {
 public:
  InputError(std::string file, std::string key, const std::string& message)
      : std::runtime_error(format(file, key, message)), file_(std::move(file)), key_(std::move(key)) {}
  const std::string& file() const { return file_; }
  const std::string& key() const { return key_; }

 private:
  static std::string format(const std::string& file, const std::string& key,
                            const std::string& message) {
    std::string s;
    if (!file.empty()) s += file + ": ";
    if (!key.empty()) s += "key '" + key + "': ";
    return s + message;
  }
  std::string file_, key_;
};

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
