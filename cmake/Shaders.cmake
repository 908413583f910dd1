# Compiles GLSL to SPIR-V 1.6 at build time and validates every module with spirv-val.
# A compile error fails the build; glslangValidator prints it as "ERROR: <file>:<line>: ...".
set(RTR_SPIRV_DIR ${CMAKE_BINARY_DIR}/shaders)

function(rtr_compile_shaders target)
  set(outputs)
  foreach(src IN LISTS ARGN)
    get_filename_component(name ${src} NAME)
    set(spv ${RTR_SPIRV_DIR}/${name}.spv)
    add_custom_command(
      OUTPUT ${spv}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${RTR_SPIRV_DIR}
      COMMAND Vulkan::glslangValidator -V --target-env vulkan1.3 --quiet
              -I${PROJECT_SOURCE_DIR}/shaders -I${PROJECT_SOURCE_DIR}/shaders/shared --depfile ${spv}.d -o ${spv} ${src}
      COMMAND ${SPIRV_VAL} --target-env vulkan1.3 ${spv}
      MAIN_DEPENDENCY ${src}
      DEPFILE ${spv}.d
      COMMENT "GLSL ${name}"
      VERBATIM)
    list(APPEND outputs ${spv})
  endforeach()
  add_custom_target(${target} ALL DEPENDS ${outputs})
endfunction()
