# Warnings are errors everywhere in pliant. Targets opt in with pliant_set_warnings(<target>).
function(pliant_set_warnings target)
  target_compile_options(${target} PRIVATE
    -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion
    -Wdouble-promotion -Wnon-virtual-dtor -Wold-style-cast -Werror)
endfunction()

# Compile options for code that runs on the controller: no exceptions, no RTTI.
function(pliant_set_realtime_flags target)
  target_compile_options(${target} PRIVATE -fno-exceptions -fno-rtti)
endfunction()
