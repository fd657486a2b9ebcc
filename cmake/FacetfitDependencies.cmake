# All third-party packages come from Debian bookworm (scripts/deps-debian.txt).
find_package(Threads REQUIRED)
find_package(TBB REQUIRED)
find_package(glm REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
if(FACETFIT_TESTS)
  find_package(GTest REQUIRED)
endif()
if(FACETFIT_BUILD_TOOLS)
  find_package(benchmark REQUIRED)
endif()
find_package(Ceres REQUIRED)  # least-squares refinement of fits on the whole measurement
# FFTW 3: Debian's CMake config for it is incomplete, so the library itself (the anisotropic extraction's
# azimuthal convolutions)
find_path(FFTW3_INCLUDE_DIR fftw3.h REQUIRED)
find_library(FFTW3_LIBRARY fftw3 REQUIRED)
find_package(OpenSSL REQUIRED)  # SHA-256 of sources (LUT metadata, bake cache)
find_package(Imath CONFIG REQUIRED)
find_package(OpenEXR CONFIG REQUIRED)  # LUTs, renders and environment maps, read and written directly
find_package(OpenImageIO CONFIG REQUIRED)  # every other image format, in the module facetfit-oiio.so
find_package(embree 3 CONFIG REQUIRED)
find_path(HWY_INCLUDE_DIR hwy/highway.h REQUIRED)  # Google Highway: SIMD lanes of the renderer's shading
# Debian installs OpenColorIO's CMake config under /usr/share/cmake.
find_package(OpenColorIO CONFIG REQUIRED PATHS /usr/share/cmake)

# Debian's imported targets list include folders that do not exist (/usr/include/opencv4), which CMake
# rejects: keep only the folders that are there.
function(facetfit_keep_existing_includes target)
  get_target_property(dirs ${target} INTERFACE_INCLUDE_DIRECTORIES)
  set(kept "")
  foreach(dir IN LISTS dirs)
    if(EXISTS "${dir}")
      list(APPEND kept "${dir}")
    endif()
  endforeach()
  list(REMOVE_DUPLICATES kept)
  set_target_properties(${target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${kept}")
endfunction()
facetfit_keep_existing_includes(OpenImageIO::OpenImageIO)
facetfit_keep_existing_includes(OpenImageIO::OpenImageIO_Util)
facetfit_keep_existing_includes(OpenColorIO::OpenColorIO)
