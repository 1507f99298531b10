// SPDX-License-Identifier: Apache-2.0
// The library's one error type.
//
// Every failure that reaches a user is an inertialnet::Error. Its kind decides the CLI's exit
// code: bad input or bad usage (a missing file, a wrong weight shape, an unknown device spec)
// exits 2; a failure of the machine or the driver (an OpenCL call that fails, out of memory)
// exits 1. OpenCL and CLBlast failures name the call, the error by name, the device and, where
// one is involved, the kernel.
#pragma once

#include <stdexcept>
#include <string>

#include "inertialnet/runtime/opencl.hpp"

namespace inertialnet {

enum class ErrorKind {
  Runtime,       // the device, the driver or the host failed: exit code 1
  InvalidInput,  // the caller asked for something impossible: exit code 2
};

class Error : public std::runtime_error {
 public:
  Error(ErrorKind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  ErrorKind kind() const noexcept { return kind_; }
  int exit_code() const noexcept { return kind_ == ErrorKind::InvalidInput ? 2 : 1; }

 private:
  ErrorKind kind_;
};

// Shorthands that read well at the call site: `throw invalid_input("…")`.
inline Error invalid_input(const std::string& message) { return Error(ErrorKind::InvalidInput, message); }
inline Error runtime_error(const std::string& message) { return Error(ErrorKind::Runtime, message); }

// "CL_OUT_OF_RESOURCES" for -5; "CL_UNKNOWN_ERROR(-1234)" for codes no specification defines.
std::string cl_error_name(cl_int code);

// CLBlast's status codes extend OpenCL's: "CL_INVALID_VALUE" for -30, "kInvalidLeadDimA" for -1016.
std::string clblast_status_name(int code);

// Where an OpenCL call was made: which device and, if any, which kernel. Filled by the runtime
// so that callers of check_cl() need not repeat it.
struct ClSite {
  std::string device;  // device name; empty when no device is involved (platform discovery)
  std::string kernel;  // "family/kernel" for enqueues and argument setting; empty otherwise
};

// Throws Error(Runtime) naming `call`, the error and the site when status != CL_SUCCESS.
// CL_INVALID_* codes that follow from arguments the library computed are still Runtime errors:
// the library validated user input before reaching the driver.
void check_cl(cl_int status, const char* call, const ClSite& site = {});

// The same for CLBlast routines (status is clblast::StatusCode cast to int).
void check_clblast(int status, const char* routine, const ClSite& site = {});

}  // namespace inertialnet

// The name of an OpenCL function as the compiler spells it: INERTIALNET_CL_NAME(clFinish) is
// "clFinish", and a misspelt name does not compile. For calls whose status is inspected before
// it is checked: check_cl(status, INERTIALNET_CL_NAME(clCreateKernel), site).
#define INERTIALNET_CL_NAME(function) (static_cast<void>(&function), #function)

// Calls `function(arguments…)`, which returns its cl_int status, and checks it; an error names
// the function. `site` is an lvalue or a parenthesised expression (a brace initialiser's comma
// would split the macro's arguments).
#define INERTIALNET_CHECK_CL(site, function, ...) ::inertialnet::check_cl(function(__VA_ARGS__), #function, site)

namespace inertialnet {

}  // namespace inertialnet
