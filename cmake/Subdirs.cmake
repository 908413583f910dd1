# Adds every immediate sub-folder of the current folder that has a CMakeLists.txt, in name order,
# so that each part of the project owns its own build file.
function(rtr_add_subdirectories)
  file(GLOB children LIST_DIRECTORIES true RELATIVE ${CMAKE_CURRENT_SOURCE_DIR} CONFIGURE_DEPENDS
       ${CMAKE_CURRENT_SOURCE_DIR}/*/CMakeLists.txt)
  list(SORT children)
  foreach(c IN LISTS children)
    get_filename_component(dir ${c} DIRECTORY)
    add_subdirectory(${dir})
  endforeach()
endfunction()
