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
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 600)
endfunction()
