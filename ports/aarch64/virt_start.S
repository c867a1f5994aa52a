/* SPDX-License-Identifier: MIT */
/* aarch64 reset for QEMU's `virt` machine run bare metal (-kernel lidet_fw.elf: QEMU starts core 0 at _start, at
 * EL1, or at EL2 with virtualization=on: then it drops to EL1). Core 0 sets the stack, the exception vectors, the
 * FP/SIMD unit (CPACR_EL1.FPEN: FP and NEON instructions trap until it is set), the MMU (an identity map: the
 * first GiB, with the UART, as Device memory, the second, the RAM, as Normal write-back memory, so that unaligned
 * and vector accesses behave as under Linux; with the MMU off every data access is Device memory), the
 * instruction counter (PMU event counter 0 on INST_RETIRED, virt_port.c), then calls fw_start
 * (ports/firmware/fw_start.c). Other cores park. Written for lidet. */

/* MAIR_EL1: attribute 0 Device-nGnRnE, attribute 1 Normal, inner and outer write-back read/write-allocate */
#define MAIR_VALUE 0xFF00
/* TCR_EL1: T0SZ 25 (39-bit addresses, the walk starts at level 1: 1 GiB blocks), TTBR0 walks inner/outer
   write-back cacheable and inner shareable, 4 KiB granule, TTBR1 walks off (EPD1), 32-bit physical addresses */
#define TCR_VALUE ((25 << 0) | (1 << 8) | (1 << 10) | (3 << 12) | (0 << 14) | (1 << 23))
/* level-1 block descriptors: valid block (0b01), AttrIndx, AP 00 (EL1 read/write), SH, AF; the Device block
   never executes (PXN, UXN) */
#define BLOCK_DEVICE ((1 << 0) | (0 << 2) | (1 << 10) | (1 << 53) | (1 << 54))
#define BLOCK_NORMAL ((1 << 0) | (1 << 2) | (3 << 8) | (1 << 10))
/* SCTLR_EL1: M (MMU), C (data cache), I (instruction cache); A (alignment checks) and SA0 off */
#define SCTLR_SET ((1 << 0) | (1 << 2) | (1 << 12))
#define SCTLR_CLEAR ((1 << 1) | (1 << 4))
/* PMU event INST_RETIRED: with `-icount shift=0` QEMU counts it exactly (virt_port.c) */
#define PMU_INST_RETIRED 0x08

    .section .text.init, "ax", %progbits
    .globl _start
_start:
    mrs     x1, mpidr_el1
    and     x1, x1, #0xff
    cbnz    x1, park
    mrs     x1, CurrentEL
    lsr     x1, x1, #2
    cmp     x1, #2
    b.ne    at_el1
    /* EL2: EL1 runs AArch64, no traps of EL1's timer and counter accesses, then enter EL1 with DAIF masked */
    mov     x1, #(1 << 31)
    msr     hcr_el2, x1
    mov     x1, #3
    msr     cnthctl_el2, x1
    msr     cntvoff_el2, xzr
    mov     x1, #0x3c5
    msr     spsr_el2, x1
    adr     x1, at_el1
    msr     elr_el2, x1
    eret
at_el1:
    ldr     x1, =__stack_top
    mov     sp, x1
    ldr     x1, =fw_vectors
    msr     vbar_el1, x1
    /* CPACR_EL1.FPEN = 0b11: FP and Advanced SIMD at EL1 and EL0 without traps */
    mov     x1, #(3 << 20)
    msr     cpacr_el1, x1
    isb
    msr     fpcr, xzr

    /* the MMU: clear the level-1 table, write the two blocks, then turn it on */
    ldr     x0, =fw_ttb
    mov     x1, x0
    add     x2, x0, #4096
1:  stp     xzr, xzr, [x1], #16
    cmp     x1, x2
    b.ne    1b
    ldr     x1, =(BLOCK_DEVICE | 0x00000000)
    str     x1, [x0]
    ldr     x1, =(BLOCK_NORMAL | 0x40000000)
    str     x1, [x0, #8]
    ldr     x1, =MAIR_VALUE
    msr     mair_el1, x1
    ldr     x1, =TCR_VALUE
    msr     tcr_el1, x1
    msr     ttbr0_el1, x0
    dsb     sy
    tlbi    vmalle1
    dsb     sy
    isb
    mrs     x1, sctlr_el1
    ldr     x2, =SCTLR_SET
    orr     x1, x1, x2
    ldr     x2, =SCTLR_CLEAR
    bic     x1, x1, x2
    msr     sctlr_el1, x1
    isb

    /* the instruction counter: event counter 0 counts INST_RETIRED at every exception level; reset, enable */
    mov     x1, #PMU_INST_RETIRED
    msr     pmevtyper0_el0, x1
    mov     x1, #1
    msr     pmcntenset_el0, x1
    mov     x1, #((1 << 1) | (1 << 0))  /* PMCR_EL0: P (reset the event counters), E (enable) */
    msr     pmcr_el0, x1
    isb

    bl      fw_start
park:
    wfe
    b       park

/* fw_spin(n), n >= 1: 2 n + 1 instructions (n x (subs, b.ne), ret), fw_port.h */
    .section .text.fw_spin, "ax", %progbits
    .globl fw_spin
    .type fw_spin, %function
    .balign 16
fw_spin:
1:  subs    w0, w0, #1
    b.ne    1b
    ret
    .size fw_spin, . - fw_spin

/* exception vectors: 16 entries of 0x80 bytes; every one reports the exception and ends the program */
    .macro VECTOR kind
    .balign 0x80
    mov     x0, #\kind
    b       trap
    .endm

    .section .text.vectors, "ax", %progbits
    .balign 2048
    .globl fw_vectors
fw_vectors:
    .irp k, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15
    VECTOR \k
    .endr
trap:
    mrs     x1, esr_el1
    mrs     x2, elr_el1
    mrs     x3, far_el1
    ldr     x4, =__stack_top
    mov     sp, x4
    bl      fw_a64_report_trap
    b       park

    .section .ttb, "aw", %nobits
    .balign 4096
    .globl fw_ttb
fw_ttb:
    .space 4096
