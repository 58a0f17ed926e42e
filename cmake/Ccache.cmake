# A compiler cache (Debian's ccache, installed by scripts/install-deps) in front of every compile,
# so that the presets, the `pip install .` build and a developer's rebuilds reuse each other's
# objects. Paths under the source tree are hashed relative to it (base_dir) and the build folder
# is left out of the hash (hash_dir), so a fresh clone elsewhere, as CI makes, hits the same cache.
# The sloppiness lets ccache cache compiles that use a precompiled header (tests/, apps/).
# PIEZOSHIFT_CCACHE=OFF, or no ccache on PATH, compiles directly.
option(PIEZOSHIFT_CCACHE "Compile through ccache when it is installed" ON)
if(PIEZOSHIFT_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  find_program(PIEZOSHIFT_CCACHE_PROGRAM ccache)
  if(PIEZOSHIFT_CCACHE_PROGRAM)
    set(CMAKE_CXX_COMPILER_LAUNCHER
        ${CMAKE_COMMAND} -E env CCACHE_BASEDIR=${PROJECT_SOURCE_DIR} CCACHE_NOHASHDIR=1
        CCACHE_SLOPPINESS=pch_defines,time_macros
        ${PIEZOSHIFT_CCACHE_PROGRAM})
  else()
    message(STATUS "piezoshift: ccache not found, compiling without a cache")
  endif()
endif()
