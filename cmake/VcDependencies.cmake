# Every dependency comes from Debian 12's packages (scripts/install-deps.sh installs them).
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(octomap REQUIRED)
find_package(spdlog REQUIRED)
find_package(fmt REQUIRED)
find_package(ZLIB REQUIRED)
find_package(BZip2 REQUIRED)
find_package(EXPAT REQUIRED)  # the E57 reader's XML section (Debian libexpat1-dev)
find_package(PNG REQUIRED)
find_package(nlohmann_json 3.11 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(Threads REQUIRED)
find_package(roaring CONFIG REQUIRED)  # sparse visibility sets (vc/visibility/voxel_set.h; Debian libroaring-dev)
find_package(PkgConfig REQUIRED)
pkg_check_modules(HWY REQUIRED IMPORTED_TARGET libhwy)
# COIN-OR CBC (coinor-libcbc-dev): the exact station selector (vc::plan only).
pkg_check_modules(CBC REQUIRED IMPORTED_TARGET cbc)
# PROJ (libproj-dev): the CRS of vc-client --crs, stations.geojson and true north (vc::report only).
pkg_check_modules(PROJ REQUIRED IMPORTED_TARGET proj)
# cairo (libcairo2-dev, which brings FreeType's libfreetype-dev): fieldsheet.pdf (vc::report only).
pkg_check_modules(CAIRO REQUIRED IMPORTED_TARGET cairo cairo-pdf cairo-ft freetype2)

# three.js r111 and its OrbitControls from Debian's libjs-three: report.html inlines them
# (core/report). Needed at build time only; the binaries carry the text.
find_file(VC_THREE_JS three.min.js PATHS /usr/share/javascript/three/build NO_DEFAULT_PATH
  DOC "three.min.js (libjs-three) for report.html")
find_file(VC_THREE_ORBIT_CONTROLS_JS OrbitControls.js PATHS /usr/share/javascript/three/examples/js/controls
  NO_DEFAULT_PATH DOC "three.js's OrbitControls.js (libjs-three) for report.html")
if(NOT EXISTS "${VC_THREE_JS}" OR NOT EXISTS "${VC_THREE_ORBIT_CONTROLS_JS}")
  message(FATAL_ERROR "report.html needs three.js from Debian's libjs-three "
    "(/usr/share/javascript/three/build/three.min.js and examples/js/controls/OrbitControls.js; found "
    "'${VC_THREE_JS}' and '${VC_THREE_ORBIT_CONTROLS_JS}'). "
    "Install it with scripts/install-deps.sh (or apt-get install libjs-three), or point "
    "-DVC_THREE_JS=... and -DVC_THREE_ORBIT_CONTROLS_JS=... at copies of three.js r111.")
endif()

# OctoMap's package config exports plain variables; wrap them in one imported target.
if(NOT TARGET vc::octomap)
  add_library(vc_octomap INTERFACE)
  target_include_directories(vc_octomap SYSTEM INTERFACE ${OCTOMAP_INCLUDE_DIRS})
  target_link_libraries(vc_octomap INTERFACE ${OCTOMAP_LIBRARIES})
  add_library(vc::octomap ALIAS vc_octomap)
endif()

if(VC_BUILD_SERVICE)
  find_package(Protobuf REQUIRED)
  find_package(gRPC CONFIG REQUIRED)
  find_program(VC_GRPC_CPP_PLUGIN grpc_cpp_plugin REQUIRED)
endif()
if(VC_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(VC_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()
