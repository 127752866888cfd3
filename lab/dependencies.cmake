# Every dependency of rocklab, found once at configure time. A missing one stops
# configuration with the Debian package that provides it (`make deps` installs them all).

function(rocklab_missing what package)
  message(FATAL_ERROR
    "rocklab: ${what} was not found. Install the Debian package '${package}' "
    "(apt-get install ${package}), or run 'make deps' to install everything rocklab needs.")
endfunction()

find_package(PkgConfig QUIET)
if(NOT PkgConfig_FOUND)
  rocklab_missing("pkg-config" "pkg-config")
endif()

find_package(Eigen3 3.3 QUIET NO_MODULE)
if(NOT Eigen3_FOUND)
  rocklab_missing("Eigen 3 (linear algebra, the DEM core)" "libeigen3-dev")
endif()

find_package(OpenMP QUIET COMPONENTS CXX)
if(NOT OpenMP_CXX_FOUND)
  rocklab_missing("OpenMP (threads in the DEM core)" "libgomp1 (part of g++)")
endif()

find_package(CGAL QUIET)
if(NOT CGAL_FOUND)
  rocklab_missing("CGAL (triangulations for the pore network)" "libcgal-dev")
endif()

find_package(VTK QUIET COMPONENTS
  RenderingOpenGL2 RenderingCore RenderingFreeType RenderingAnnotation ChartsCore ViewsContext2D
  RenderingContextOpenGL2 InteractionStyle IOImage IOXML FiltersSources CommonCore
  CommonDataModel IOXMLParser)
if(NOT VTK_FOUND)
  rocklab_missing("VTK 9 (charts, snapshots, ParaView export)" "libvtk9-dev")
endif()

pkg_check_modules(OSMESA QUIET IMPORTED_TARGET osmesa)
if(NOT OSMESA_FOUND)
  rocklab_missing("OSMesa (off-screen OpenGL for snapshots)" "libosmesa6-dev")
endif()

pkg_check_modules(FFTW3 QUIET IMPORTED_TARGET fftw3)
if(NOT FFTW3_FOUND)
  rocklab_missing("FFTW 3 (spectra and arrival picking)" "libfftw3-dev")
endif()

# CHOLMOD (SuiteSparse): the supernodal Cholesky of the pore network's pressure system, as
# Yade's FlowEngine uses; Eigen's simplicial one fills in badly on 3D networks (45 s against
# CHOLMOD's under a second at 116,000 pores). Debian ships no CMake or pkg-config file.
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_library(CHOLMOD_LIBRARY cholmod)
if(NOT CHOLMOD_INCLUDE_DIR OR NOT CHOLMOD_LIBRARY)
  rocklab_missing("CHOLMOD (sparse Cholesky for the pore network)" "libsuitesparse-dev")
endif()
add_library(rocklab_cholmod INTERFACE)
target_include_directories(rocklab_cholmod INTERFACE ${CHOLMOD_INCLUDE_DIR})
target_link_libraries(rocklab_cholmod INTERFACE ${CHOLMOD_LIBRARY})

find_package(SQLite3 QUIET)
if(NOT SQLite3_FOUND)
  rocklab_missing("SQLite 3 (the lab notebook)" "libsqlite3-dev")
endif()

find_package(toml11 QUIET)
if(NOT toml11_FOUND)
  rocklab_missing("toml11 (protocol files)" "libtoml11-dev")
endif()

find_package(CLI11 QUIET)
if(NOT CLI11_FOUND)
  rocklab_missing("CLI11 (the rocklab command line)" "libcli11-dev")
endif()

if(ROCKLAB_TESTS)
  find_package(GTest QUIET)
  if(NOT GTest_FOUND)
    rocklab_missing("GoogleTest (the test suite)" "libgtest-dev")
  endif()
endif()

find_package(benchmark QUIET)
if(NOT benchmark_FOUND)
  rocklab_missing("Google Benchmark (kernel micro-benchmarks)" "libbenchmark-dev")
endif()

find_program(ROCKLAB_SQLITE3_PROGRAM sqlite3)
if(NOT ROCKLAB_SQLITE3_PROGRAM)
  rocklab_missing("the sqlite3 shell (querying the notebook by hand)" "sqlite3")
endif()
