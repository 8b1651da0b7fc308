# CMake package for Tessera's C ABI: find_package(Tessera) gives the imported target
# Tessera::tessera (the cargo-built shared library, include/tessera.h and include/tessera.hpp,
# and the Vulkan headers tessera.h includes).
#
# Build the library first:  cargo build --release -p tessera-capi
# then point CMake here:     cmake -DTessera_DIR=<tessera>/cmake ...
# The library is looked for in $CARGO_TARGET_DIR (or <tessera>/target), release before debug;
# set TESSERA_LIBRARY to a libtessera_capi.so (or .a, with its system libraries) to choose.
include(CMakeFindDependencyMacro)
find_dependency(Vulkan)

get_filename_component(_tessera_root "${CMAKE_CURRENT_LIST_DIR}/.." ABSOLUTE)
if(DEFINED ENV{CARGO_TARGET_DIR})
  set(_tessera_target "$ENV{CARGO_TARGET_DIR}")
else()
  set(_tessera_target "${_tessera_root}/target")
endif()
find_library(TESSERA_LIBRARY NAMES tessera_capi
  PATHS "${_tessera_target}/release" "${_tessera_target}/debug" NO_DEFAULT_PATH)
if(NOT TESSERA_LIBRARY)
  set(Tessera_FOUND FALSE)
  set(Tessera_NOT_FOUND_MESSAGE
    "libtessera_capi not found under ${_tessera_target}: run `cargo build --release -p tessera-capi` or set TESSERA_LIBRARY")
  return()
endif()

if(NOT TARGET Tessera::tessera)
  if(TESSERA_LIBRARY MATCHES "\\.a$")
    add_library(Tessera::tessera STATIC IMPORTED)
    # A Rust static library needs the system libraries the standard library uses.
    set_property(TARGET Tessera::tessera PROPERTY INTERFACE_LINK_LIBRARIES
      Vulkan::Headers pthread dl m)
  else()
    add_library(Tessera::tessera SHARED IMPORTED)
    set_property(TARGET Tessera::tessera PROPERTY INTERFACE_LINK_LIBRARIES Vulkan::Headers)
  endif()
  set_target_properties(Tessera::tessera PROPERTIES
    IMPORTED_LOCATION "${TESSERA_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${_tessera_root}/include")
endif()
set(Tessera_FOUND TRUE)
