/* Cortex-M4F start-up for the STM32F405 (QEMU netduinoplus2): vector table, reset handler that
   copies .data, clears .bss, enables the FPU (CP10/CP11) and runs static constructors, then
   main(). Every exception but reset stops the program with a semihosting exit code. */
#include <stdint.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
extern void (*__init_array_start[])(void);
extern void (*__init_array_end[])(void);
int main(void);
void semihosting_exit(int status);

void Reset_Handler(void);
void Fault_Handler(void);

__attribute__((section(".isr_vector"), used)) void (*const g_vector_table[16])(void) = {
    (void (*)(void))(&_estack),
    Reset_Handler,
    Fault_Handler, /* NMI */
    Fault_Handler, /* HardFault */
    Fault_Handler, /* MemManage */
    Fault_Handler, /* BusFault */
    Fault_Handler, /* UsageFault */
    0, 0, 0, 0,
    Fault_Handler, /* SVCall */
    Fault_Handler, /* DebugMonitor */
    0,
    Fault_Handler, /* PendSV */
    Fault_Handler, /* SysTick: never enabled as an interrupt */
};

void Fault_Handler(void) {
  semihosting_exit(3);
  for (;;) {
  }
}

void Reset_Handler(void) {
  /* The FPU is off at reset: grant full access to CP10 and CP11 before any float instruction. */
  volatile uint32_t* const cpacr = (volatile uint32_t*)0xE000ED88u;
  *cpacr |= (0xFu << 20);
  __asm volatile("dsb\n\tisb" ::: "memory");

  const uint32_t* src = &_sidata;
  for (uint32_t* dst = &_sdata; dst < &_edata;)
    *dst++ = *src++;
  for (uint32_t* dst = &_sbss; dst < &_ebss;)
    *dst++ = 0;
  for (void (**f)(void) = __init_array_start; f < __init_array_end; ++f)
    (*f)();

  semihosting_exit(main());
  for (;;) {
  }
}
