/* SPDX-License-Identifier: MIT */
/* RISC-V reset for QEMU's `virt` machine (-bios none: QEMU jumps to _start in machine mode on every hart).
 * Hart 0 sets gp, sp, the trap vector and (float builds) the FPU, then calls fw_start (ports/firmware/fw_start.c);
 * other harts park. Written for lidet. */
    /* CSR instructions (Zicsr): implied by F on rv32imafc, spelled out for rv32imac */
    .option arch, +zicsr
    .section .text.init, "ax", @progbits
    .globl _start
_start:
    .option push
    .option norelax
    la      gp, __global_pointer$
    .option pop
    csrr    t0, mhartid
    bnez    t0, park
    la      sp, __stack_top
    la      t0, fw_trap_entry
    csrw    mtvec, t0
#ifdef __riscv_flen
    /* mstatus.FS = Initial: floating-point instructions trap until this is set */
    li      t0, (1 << 13)
    csrs    mstatus, t0
    csrw    fcsr, zero
#endif
    /* picolibc keeps errno in thread-local storage: point tp at the TLS block of the linker script */
    la      tp, __tls_base
    call    fw_start
park:
    wfi
    j       park

    .align 2
fw_trap_entry:
    csrr    a0, mcause
    csrr    a1, mepc
    csrr    a2, mtval
    la      sp, __stack_top
    call    fw_virt_report_trap
    j       park
