# ms_library(NAME DIR DEPS...): a static library of every .cpp in DIR (except
# files ending in _main.cpp), re-globbed at build time so adding a file needs
# no CMake edit. An INTERFACE library while the folder has no sources yet.
function(ms_library name)
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  list(FILTER sources EXCLUDE REGEX "_main\\.cpp$")
  if(sources)
    add_library(${name} STATIC ${sources})
    target_link_libraries(${name} PUBLIC ${ARGN})
  else()
    add_library(${name} INTERFACE)
    target_link_libraries(${name} INTERFACE ${ARGN})
  endif()
endfunction()

# ms_test(NAME DEPS...): one GoogleTest binary of every *_test.cpp in the
# current folder, registered with CTest test by test.
function(ms_test name)
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*_test.cpp)
  if(NOT sources)
    return()
  endif()
  add_executable(${name} ${sources})
  target_link_libraries(${name} PRIVATE ${ARGN} GTest::gtest_main GTest::gmock)
  target_compile_definitions(${name} PRIVATE
    MESHSTREAM_SOURCE_DIR="${CMAKE_SOURCE_DIR}"
    MESHSTREAM_BINARY_DIR="${CMAKE_BINARY_DIR}")
  # Tests that drive the real binaries (servers, clients, tools, docs,
  # web servers) are glue whose compile time is mostly templates (gtest,
  # <regex>, Asio): at -O1 a file compiles in about 0.6x the time (28 s ->
  # 18 s for tool_cli_test), and CI builds every test from scratch. The
  # algorithmic tests (codec, asa, mesh, metrics) compute in their own code
  # and keep the build type's optimisation.
  if(NOT name MATCHES "^ms_(codec|codec_memory|asa|mesh|metrics)_tests$")
    target_compile_options(${name} PRIVATE $<$<CONFIG:Release>:-O1>)
  endif()
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 600)
endfunction()
