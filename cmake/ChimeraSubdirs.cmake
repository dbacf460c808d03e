# Adds every direct subfolder of the current folder that has a CMakeLists.txt, in name order,
# so that a new module or test folder needs no edit elsewhere.
macro(chimera_add_subdirectories)
  file(GLOB _chimera_children LIST_DIRECTORIES true RELATIVE ${CMAKE_CURRENT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR}/*)
  list(SORT _chimera_children)
  foreach(_child IN LISTS _chimera_children)
    if(IS_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/${_child} AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${_child}/CMakeLists.txt)
      add_subdirectory(${_child})
    endif()
  endforeach()
endmacro()
