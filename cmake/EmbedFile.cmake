# miner_embed_file(<out.cpp> <namespace> <symbol> <file>)
# Writes <out.cpp> defining `extern const unsigned char <symbol>[]` (the file's bytes
# followed by a 0, so text files can be read as C strings) and
# `extern const std::size_t <symbol>Size` (the byte count, without the 0), and re-runs
# CMake when <file> changes. Used for the sGAN weights and the report's JavaScript, so
# the `miner` binary runs anywhere without its source tree.
function(miner_embed_file out_cpp ns symbol file)
  if(NOT EXISTS ${file})
    message(FATAL_ERROR "miner_embed_file: ${file} not found (run ci/setup.sh to install the packages)")
  endif()
  file(READ ${file} _hex HEX)
  string(LENGTH "${_hex}" _hex_len)
  math(EXPR _bytes "${_hex_len} / 2")
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," _array "${_hex}")
  file(WRITE ${out_cpp}.tmp
    "// Generated from ${file} by cmake/EmbedFile.cmake.\n"
    "#include <cstddef>\nnamespace ${ns} {\n"
    "extern const unsigned char ${symbol}[] = {${_array}0x00};\n"
    "extern const std::size_t ${symbol}Size = ${_bytes};\n}\n")
  configure_file(${out_cpp}.tmp ${out_cpp} COPYONLY)
  file(REMOVE ${out_cpp}.tmp)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${file})
endfunction()
