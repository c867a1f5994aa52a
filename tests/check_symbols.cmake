# SPDX-License-Identifier: MIT
# Fails if the static library references heap, stdio or double-precision libm functions.
# Usage: cmake -DLIB=liblidet.a -DNM=nm -P check_symbols.cmake
execute_process(COMMAND ${NM} -u ${LIB} OUTPUT_VARIABLE undef RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "nm failed on ${LIB}")
endif()
set(forbidden malloc calloc realloc free aligned_alloc posix_memalign
    printf fprintf sprintf snprintf vprintf vfprintf vsprintf vsnprintf puts fputs fputc putc putchar
    fopen fclose fread fwrite fflush perror stdout stderr stdin fgets getchar scanf sscanf
    sin cos tan asin acos atan atan2 sqrt exp log pow floor ceil fabs fmod round)
set(bad "")
string(REPLACE "\n" ";" lines "${undef}")
foreach(line ${lines})
  string(STRIP "${line}" line)
  string(REGEX REPLACE "^U[ \t]+" "" sym "${line}")
  string(REGEX REPLACE "@.*$" "" sym "${sym}")
  list(FIND forbidden "${sym}" idx)
  if(idx GREATER -1)
    list(APPEND bad ${sym})
  endif()
endforeach()
if(bad)
  list(REMOVE_DUPLICATES bad)
  message(FATAL_ERROR "liblidet references forbidden symbols: ${bad}")
endif()
message(STATUS "liblidet: no heap, stdio or double libm references")
