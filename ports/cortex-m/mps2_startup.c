/* SPDX-License-Identifier: MIT */
/* Cortex-M reset for the Arm MPS2 boards QEMU models (mps2-an385 Cortex-M3, mps2-an386 Cortex-M4F,
 * mps2-an500 Cortex-M7; and ARMv6-M code for the Cortex-M0+ run on the AN385's M3): the vector table, the
 * reset handler (FPU on, counter on, then fw_start) and one fault handler that reports the fault and stops.
 * Written for lidet; no CMSIS needed. */
#include <stdint.h>

#include "fw_port.h"

typedef void (*fw_vector_t)(void);

extern uint32_t __stack_top[];
void fw_start(void);
void fw_mps2_counter_start(void);
void fw_mps2_timer0_irq(void);
void fw_mps2_report_fault(uint32_t exc, const uint32_t *frame);

void Reset_Handler(void);
void Fault_Handler(void);

#define SCB_CPACR (*(volatile uint32_t *)0xE000ED88u)
#define SCB_VTOR (*(volatile uint32_t *)0xE000ED08u)

void Reset_Handler(void)
{
#if defined(__ARM_FP)
    /* CP10 and CP11 (the FPU) full access, before the first floating-point instruction */
    SCB_CPACR |= (0xFu << 20);
    __asm__ volatile("dsb\n\tisb" ::: "memory");
#endif
    fw_mps2_counter_start();
    fw_start();
    for (;;)
    {
    }
}

/* Every exception but reset: which one (IPSR) and the stacked frame (PC at word 6), then exit. The firmware
 * runs on the main stack only (no PSP). ARMv6-M instructions only, so the Cortex-M0+ build shares it. */
__attribute__((naked)) void Fault_Handler(void)
{
    __asm__ volatile("mrs r0, ipsr\n\t"
                     "mrs r1, msp\n\t"
                     "ldr r2, =fw_mps2_report_fault\n\t"
                     "bx r2\n\t"
                     ".ltorg\n\t");
}

/* 16 core exceptions, then the board's interrupts up to timer 0 (IRQ 8, the instruction counter's wrap);
 * the others stay disabled. */
__attribute__((section(".vectors"), used)) const fw_vector_t fw_vectors[16 + 9] = {
    (fw_vector_t)(uintptr_t)__stack_top, /* initial MSP */
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
    Fault_Handler, /* SysTick */
    Fault_Handler, Fault_Handler, Fault_Handler, Fault_Handler, /* IRQ 0-3: UART 0-1 */
    Fault_Handler, Fault_Handler, Fault_Handler, Fault_Handler, /* IRQ 4-7 */
    fw_mps2_timer0_irq,                                         /* IRQ 8: CMSDK timer 0 */
};
