# Sanitizer and fuzzing build modes (docs/testing.md "Sanitizers", docs/fuzzing.md).
#
#   -DWHITTED_SANITIZE=address,undefined   AddressSanitizer + UndefinedBehaviorSanitizer
#   -DWHITTED_SANITIZE=thread              ThreadSanitizer
#   -DWHITTED_FUZZ=ON                      libFuzzer harnesses in fuzz/ (clang only; combine with
#                                          address,undefined so the fuzzer sees memory errors)
#
# Flags go on every target of the project (libraries included) so that the code under test is
# instrumented; Debian's Embree, TBB, OIIO, OCIO and tinygltf stay uninstrumented (see the
# suppression files next to this one and docs/testing.md).
set(WHITTED_SANITIZE "" CACHE STRING "Sanitizers to build with: 'address,undefined', 'thread' or empty")
option(WHITTED_FUZZ "Build the libFuzzer harnesses in fuzz/ (needs clang)" OFF)

if(WHITTED_SANITIZE)
  string(REPLACE " " "" _whitted_san "${WHITTED_SANITIZE}")
  string(REPLACE "," ";" _whitted_san_list "${_whitted_san}")
  foreach(_s IN LISTS _whitted_san_list)
    if(NOT _s MATCHES "^(address|undefined|thread|leak)$")
      message(FATAL_ERROR "WHITTED_SANITIZE: unknown sanitizer '${_s}' (use address,undefined or thread)")
    endif()
  endforeach()
  if("thread" IN_LIST _whitted_san_list AND "address" IN_LIST _whitted_san_list)
    message(FATAL_ERROR "WHITTED_SANITIZE: thread cannot be combined with address")
  endif()
  set(_whitted_san_flags -fsanitize=${_whitted_san} -fno-omit-frame-pointer)
  if("undefined" IN_LIST _whitted_san_list)
    # Every UB report fails the test (instead of printing and going on). vptr needs RTTI of the
    # uninstrumented libraries' classes and reports false positives across them: left out.
    list(APPEND _whitted_san_flags -fno-sanitize-recover=undefined -fno-sanitize=vptr)
  endif()
  add_compile_options(${_whitted_san_flags})
  add_link_options(${_whitted_san_flags})
  message(STATUS "whitted: sanitizers ${_whitted_san}")
endif()

if(WHITTED_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "WHITTED_FUZZ needs clang (libFuzzer): configure with -DCMAKE_CXX_COMPILER=clang++")
  endif()
  # Coverage instrumentation for everything; the harness executables link libFuzzer's main.
  add_compile_options(-fsanitize=fuzzer-no-link)
  add_compile_definitions(WHITTED_FUZZING=1)
  message(STATUS "whitted: libFuzzer harnesses enabled")
endif()
