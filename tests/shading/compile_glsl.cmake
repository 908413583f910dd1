# cmake -P script: compile one GLSL file for Vulkan 1.3 and run spirv-val on it; fails on either error.
execute_process(COMMAND ${GLSLANG} -V --target-env vulkan1.3 -I${INC} -o ${OUT} ${SRC} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "glslangValidator failed on ${SRC}")
endif()
execute_process(COMMAND ${SPIRV_VAL} --target-env vulkan1.3 ${OUT} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "spirv-val failed on ${OUT}")
endif()
