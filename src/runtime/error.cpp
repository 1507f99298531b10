#include "inertialnet/runtime/error.hpp"

#include <sstream>

namespace inertialnet {

std::string cl_error_name(cl_int code) {
  switch (code) {
#define INERTIALNET_CL_ERROR(name) \
  case name:                       \
    return #name;
    INERTIALNET_CL_ERROR(CL_SUCCESS)
    INERTIALNET_CL_ERROR(CL_DEVICE_NOT_FOUND)
    INERTIALNET_CL_ERROR(CL_DEVICE_NOT_AVAILABLE)
    INERTIALNET_CL_ERROR(CL_COMPILER_NOT_AVAILABLE)
    INERTIALNET_CL_ERROR(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    INERTIALNET_CL_ERROR(CL_OUT_OF_RESOURCES)
    INERTIALNET_CL_ERROR(CL_OUT_OF_HOST_MEMORY)
    INERTIALNET_CL_ERROR(CL_PROFILING_INFO_NOT_AVAILABLE)
    INERTIALNET_CL_ERROR(CL_MEM_COPY_OVERLAP)
    INERTIALNET_CL_ERROR(CL_IMAGE_FORMAT_MISMATCH)
    INERTIALNET_CL_ERROR(CL_IMAGE_FORMAT_NOT_SUPPORTED)
    INERTIALNET_CL_ERROR(CL_BUILD_PROGRAM_FAILURE)
    INERTIALNET_CL_ERROR(CL_MAP_FAILURE)
    INERTIALNET_CL_ERROR(CL_MISALIGNED_SUB_BUFFER_OFFSET)
    INERTIALNET_CL_ERROR(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
    INERTIALNET_CL_ERROR(CL_COMPILE_PROGRAM_FAILURE)
    INERTIALNET_CL_ERROR(CL_LINKER_NOT_AVAILABLE)
    INERTIALNET_CL_ERROR(CL_LINK_PROGRAM_FAILURE)
    INERTIALNET_CL_ERROR(CL_DEVICE_PARTITION_FAILED)
    INERTIALNET_CL_ERROR(CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
    INERTIALNET_CL_ERROR(CL_INVALID_VALUE)
    INERTIALNET_CL_ERROR(CL_INVALID_DEVICE_TYPE)
    INERTIALNET_CL_ERROR(CL_INVALID_PLATFORM)
    INERTIALNET_CL_ERROR(CL_INVALID_DEVICE)
    INERTIALNET_CL_ERROR(CL_INVALID_CONTEXT)
    INERTIALNET_CL_ERROR(CL_INVALID_QUEUE_PROPERTIES)
    INERTIALNET_CL_ERROR(CL_INVALID_COMMAND_QUEUE)
    INERTIALNET_CL_ERROR(CL_INVALID_HOST_PTR)
    INERTIALNET_CL_ERROR(CL_INVALID_MEM_OBJECT)
    INERTIALNET_CL_ERROR(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR)
    INERTIALNET_CL_ERROR(CL_INVALID_IMAGE_SIZE)
    INERTIALNET_CL_ERROR(CL_INVALID_SAMPLER)
    INERTIALNET_CL_ERROR(CL_INVALID_BINARY)
    INERTIALNET_CL_ERROR(CL_INVALID_BUILD_OPTIONS)
    INERTIALNET_CL_ERROR(CL_INVALID_PROGRAM)
    INERTIALNET_CL_ERROR(CL_INVALID_PROGRAM_EXECUTABLE)
    INERTIALNET_CL_ERROR(CL_INVALID_KERNEL_NAME)
    INERTIALNET_CL_ERROR(CL_INVALID_KERNEL_DEFINITION)
    INERTIALNET_CL_ERROR(CL_INVALID_KERNEL)
    INERTIALNET_CL_ERROR(CL_INVALID_ARG_INDEX)
    INERTIALNET_CL_ERROR(CL_INVALID_ARG_VALUE)
    INERTIALNET_CL_ERROR(CL_INVALID_ARG_SIZE)
    INERTIALNET_CL_ERROR(CL_INVALID_KERNEL_ARGS)
    INERTIALNET_CL_ERROR(CL_INVALID_WORK_DIMENSION)
    INERTIALNET_CL_ERROR(CL_INVALID_WORK_GROUP_SIZE)
    INERTIALNET_CL_ERROR(CL_INVALID_WORK_ITEM_SIZE)
    INERTIALNET_CL_ERROR(CL_INVALID_GLOBAL_OFFSET)
    INERTIALNET_CL_ERROR(CL_INVALID_EVENT_WAIT_LIST)
    INERTIALNET_CL_ERROR(CL_INVALID_EVENT)
    INERTIALNET_CL_ERROR(CL_INVALID_OPERATION)
    INERTIALNET_CL_ERROR(CL_INVALID_GL_OBJECT)
    INERTIALNET_CL_ERROR(CL_INVALID_BUFFER_SIZE)
    INERTIALNET_CL_ERROR(CL_INVALID_MIP_LEVEL)
    INERTIALNET_CL_ERROR(CL_INVALID_GLOBAL_WORK_SIZE)
    INERTIALNET_CL_ERROR(CL_INVALID_PROPERTY)
    INERTIALNET_CL_ERROR(CL_INVALID_IMAGE_DESCRIPTOR)
    INERTIALNET_CL_ERROR(CL_INVALID_COMPILER_OPTIONS)
    INERTIALNET_CL_ERROR(CL_INVALID_LINKER_OPTIONS)
    INERTIALNET_CL_ERROR(CL_INVALID_DEVICE_PARTITION_COUNT)
#undef INERTIALNET_CL_ERROR
    // Codes of later OpenCL versions and of the ICD loader, by number so the 1.2 headers suffice.
    case -69: return "CL_INVALID_PIPE_SIZE";
    case -70: return "CL_INVALID_DEVICE_QUEUE";
    case -71: return "CL_INVALID_SPEC_ID";
    case -72: return "CL_MAX_SIZE_RESTRICTION_EXCEEDED";
    case -1001: return "CL_PLATFORM_NOT_FOUND_KHR";
    default: break;
  }
  return "CL_UNKNOWN_ERROR(" + std::to_string(code) + ")";
}

std::string clblast_status_name(int code) {
  // Codes above -1000 are OpenCL's own; CLBlast adds clBLAS-compatible and private ones.
  if (code > -1000) return cl_error_name(code);
  switch (code) {
    case -1024: return "kNotImplemented";
    case -1022: return "kInvalidMatrixA";
    case -1021: return "kInvalidMatrixB";
    case -1020: return "kInvalidMatrixC";
    case -1019: return "kInvalidVectorX";
    case -1018: return "kInvalidVectorY";
    case -1017: return "kInvalidDimension";
    case -1016: return "kInvalidLeadDimA";
    case -1015: return "kInvalidLeadDimB";
    case -1014: return "kInvalidLeadDimC";
    case -1013: return "kInvalidIncrementX";
    case -1012: return "kInvalidIncrementY";
    case -1011: return "kInsufficientMemoryA";
    case -1010: return "kInsufficientMemoryB";
    case -1009: return "kInsufficientMemoryC";
    case -1008: return "kInsufficientMemoryX";
    case -1007: return "kInsufficientMemoryY";
    case -2050: return "kInsufficientMemoryTemp";
    case -2049: return "kInvalidBatchCount";
    case -2048: return "kInvalidOverrideKernel";
    case -2047: return "kMissingOverrideParameter";
    case -2046: return "kInvalidLocalMemUsage";
    case -2045: return "kNoHalfPrecision";
    case -2044: return "kNoDoublePrecision";
    case -2043: return "kInvalidVectorScalar";
    case -2042: return "kInsufficientMemoryScalar";
    case -2041: return "kDatabaseError";
    case -2040: return "kUnknownError";
    case -2039: return "kUnexpectedError";
    default: break;
  }
  return "CLBLAST_UNKNOWN_STATUS(" + std::to_string(code) + ")";
}

namespace {
std::string describe(const char* library, const char* call, const std::string& name, int code,
                     const ClSite& site) {
  std::ostringstream message;
  message << library << " call " << call << " failed with " << name << " (" << code << ")";
  if (!site.device.empty()) message << " on device '" << site.device << "'";
  if (!site.kernel.empty()) message << " in kernel '" << site.kernel << "'";
  return message.str();
}
}  // namespace

void check_cl(cl_int status, const char* call, const ClSite& site) {
  if (status == CL_SUCCESS) return;
  throw runtime_error(describe("OpenCL", call, cl_error_name(status), status, site));
}

void check_clblast(int status, const char* routine, const ClSite& site) {
  if (status == 0) return;
  throw runtime_error(describe("CLBlast", routine, clblast_status_name(status), status, site));
}

}  // namespace inertialnet
