# ctest driver (test exported_symbols): libcollide.so exports exactly the public API.
#   cmake -DLIBRARY=<libcollide.so> -DNM=<nm> -DHEADER_DIR=<libcollide/include/collide> -P check_exports.cmake
# The public API is every function declared LC_API in the public headers (HEADER_DIR/*.h). It fails
#   - when a function declared in a public header lacks LC_API,
#   - when a defined dynamic symbol of the library (nm -D --defined-only; any type but the linker's
#     absolute 'A' markers) does not start with lc_, or is an lc_ function not declared LC_API
#     (an internal function leaked: the internal ones are named lc_ too),
#   - when a public function, lc_world_create and lc_version among them, is not exported.
cmake_minimum_required(VERSION 3.16)   # script mode: the policies of the project (IN_LIST)
foreach(var LIBRARY HEADER_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "check_exports.cmake: -D${var}=... is required")
  endif()
endforeach()
if(NOT NM)
  find_program(NM nm)
  if(NOT NM)
    message(FATAL_ERROR "check_exports.cmake: nm not found")
  endif()
endif()

# ---- the public functions: declarations at the start of a line in the public headers
file(GLOB headers "${HEADER_DIR}/*.h")
set(public "")
set(errors "")
foreach(h ${headers})
  file(STRINGS "${h}" lines REGEX "^[A-Za-z_].*[ *]lc_[a-z0-9_]+\\(")
  foreach(line IN LISTS lines)
    if(line MATCHES "^#|^typedef")
      continue()
    endif()
    string(REGEX MATCH "[ *](lc_[a-z0-9_]+)\\(" m "${line}")
    set(name "${CMAKE_MATCH_1}")
    if(line MATCHES "^LC_API ")
      list(APPEND public "${name}")
    else()
      get_filename_component(hname "${h}" NAME)
      list(APPEND errors "${name} is declared in collide/${hname} without LC_API")
    endif()
  endforeach()
endforeach()
list(REMOVE_DUPLICATES public)
list(LENGTH public n_public)
foreach(required lc_world_create lc_version)
  if(NOT required IN_LIST public)
    list(APPEND errors "${required} is not declared LC_API in ${HEADER_DIR}")
  endif()
endforeach()

# ---- what the library exports
execute_process(COMMAND "${NM}" -D --defined-only "${LIBRARY}"
                OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "${NM} -D --defined-only ${LIBRARY} failed (${rc}): ${err}")
endif()
string(REPLACE "\n" ";" out_lines "${out}")
set(exported "")
foreach(line IN LISTS out_lines)
  # "<address> <type> <name>[@version]"
  if(NOT line MATCHES "^[0-9a-fA-F]* *([A-Za-z]) ([^ @]+)")
    continue()
  endif()
  set(type "${CMAKE_MATCH_1}")
  set(name "${CMAKE_MATCH_2}")
  if(type STREQUAL "A")
    continue()   # absolute markers some linkers add (_edata, _end, __bss_start), not code or data
  endif()
  list(APPEND exported "${name}")
  if(NOT name MATCHES "^lc_")
    list(APPEND errors "exported symbol ${name} (type ${type}) does not start with lc_")
  elseif(NOT name IN_LIST public)
    list(APPEND errors "exported symbol ${name} (type ${type}) is not declared LC_API in a public header")
  endif()
endforeach()
foreach(name IN LISTS public)
  if(NOT name IN_LIST exported)
    list(APPEND errors "public function ${name} is not exported by ${LIBRARY}")
  endif()
endforeach()

list(LENGTH exported n_exported)
if(errors)
  list(LENGTH errors n_errors)
  string(REPLACE ";" "\n  " text "${errors}")
  message(FATAL_ERROR "${n_errors} problem(s) with the exports of ${LIBRARY} "
                      "(${n_exported} defined dynamic symbols, ${n_public} public functions):\n  ${text}")
endif()
message(STATUS "${LIBRARY}: exports exactly the ${n_public} public functions")
