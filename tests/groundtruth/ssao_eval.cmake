# SPDX-License-Identifier: MIT
# The evaluation tool build/bin/ssao_eval (ssao_eval.cpp). Included by tests/groundtruth and, when
# the tests are not built, by benchmarks/; needs the targets ssao_tools and ssao_reference.
# The C API is called through the shared library (ssao, linked before ssao_reference's
# ssao_static so that every ssao_* symbol resolves to libssao.so); the references use the core's
# camera model from ssao_static.
if(NOT TARGET ssao_eval)
  add_executable(ssao_eval ${CMAKE_CURRENT_LIST_DIR}/ssao_eval.cpp)
  target_link_libraries(ssao_eval PRIVATE ssao_tools ssao ssao_reference ssao_warnings)
endif()
