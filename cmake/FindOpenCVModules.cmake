# Debian's per-module OpenCV packages (libopencv-core-dev, ...) ship headers and
# libraries but no OpenCVConfig.cmake (that comes with the heavy libopencv-dev
# meta package). This finds the modules asked for and defines imported targets
# opencv_<module>.
#   find_package(OpenCVModules REQUIRED COMPONENTS core imgproc)
find_path(OpenCVModules_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4)
set(_missing "")
foreach(_module IN LISTS OpenCVModules_FIND_COMPONENTS)
  find_library(OpenCVModules_${_module}_LIBRARY NAMES opencv_${_module})
  if(OpenCVModules_${_module}_LIBRARY AND OpenCVModules_INCLUDE_DIR)
    set(OpenCVModules_${_module}_FOUND TRUE)
    if(NOT TARGET opencv_${_module})
      add_library(opencv_${_module} UNKNOWN IMPORTED)
      set_target_properties(opencv_${_module} PROPERTIES
        IMPORTED_LOCATION "${OpenCVModules_${_module}_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${OpenCVModules_INCLUDE_DIR}")
    endif()
  else()
    list(APPEND _missing ${_module})
  endif()
endforeach()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(OpenCVModules
  REQUIRED_VARS OpenCVModules_INCLUDE_DIR
  HANDLE_COMPONENTS
  REASON_FAILURE_MESSAGE "missing OpenCV modules: ${_missing} (apt install libopencv-<module>-dev)")
