/* The recorded test vector (firmware/include/piezoshift/firmware/test_vector.hpp), linked into
   flash byte for byte. test_vector.bin is found on the assembler's include path (-Wa,-I). */
  .section .rodata.test_vector, "a"
  .balign 8
  .global g_test_vector_begin
  .type g_test_vector_begin, %object
g_test_vector_begin:
  .incbin "test_vector.bin"
  .global g_test_vector_end
g_test_vector_end:
  .size g_test_vector_begin, g_test_vector_end - g_test_vector_begin
