/* Exception vectors and reset entry of the Cortex-R5F (ARMv7-R) on QEMU's
 * xlnx-zcu102. ARM state throughout this file: an R5 takes exceptions in ARM
 * state unless SCTLR.TE is set, which the reset code clears. The C++ part of
 * the start-up (.data, .bss, constructors, main) is in startup.cpp. */

    .syntax unified
    .arch armv7-r
    .fpu vfpv3-d16
    .arm

/* CPSR mode numbers and the interrupt masks. */
    .equ MODE_FIQ, 0x11
    .equ MODE_IRQ, 0x12
    .equ MODE_SVC, 0x13
    .equ MODE_ABT, 0x17
    .equ MODE_UND, 0x1B
    .equ MODE_SYS, 0x1F
    .equ MASK_IRQ_FIQ, 0xC0

/* SCTLR bits the reset code sets or clears. */
    .equ SCTLR_M, (1 << 0)   /* MPU */
    .equ SCTLR_C, (1 << 2)   /* data cache */
    .equ SCTLR_I, (1 << 12)  /* instruction cache */
    .equ SCTLR_V, (1 << 13)  /* high vectors at 0xFFFF0000 */
    .equ SCTLR_TE, (1 << 30) /* exceptions in Thumb state */

/* MPU regions (RGNR, DRBAR, DRSR, DRACR). A region covers 2^(N+1) bytes
 * for a DRSR size field of N, at a base aligned to its size; where regions
 * overlap, the higher number wins.
 *   0: the DDR's low 2 GiB (program, data, stacks): normal memory, write-back
 *      write-allocate cacheable, full access, executable.
 *   1: the low-power domain's peripherals, 8 MiB at 0xFF000000 (uart0,
 *      can0, can1, the timers): device memory, never executed.
 *   2: the 32 bytes both R5F cores share (.core_shared, second_core.hpp):
 *      normal memory, shareable and not cacheable, never executed. The two
 *      cores' data caches are not coherent: a word one core writes through
 *      its cache the other might never see. */
    .equ MPU_REGION_MEMORY, 0
    .equ MPU_MEMORY_BASE, 0x00000000
    .equ MPU_MEMORY_SIZE_ENABLE, (30 << 1) | 1
    .equ MPU_MEMORY_ACCESS, (0x3 << 8) | (0x1 << 3) | (1 << 1) | (1 << 0)
    .equ MPU_REGION_PERIPHERALS, 1
    .equ MPU_PERIPHERALS_BASE, 0xFF000000
    .equ MPU_PERIPHERALS_SIZE_ENABLE, (22 << 1) | 1
    .equ MPU_PERIPHERALS_ACCESS, (1 << 12) | (0x3 << 8) | (1 << 0)
    .equ MPU_REGION_CORE_SHARED, 2
    .equ MPU_CORE_SHARED_SIZE_ENABLE, (4 << 1) | 1
    .equ MPU_CORE_SHARED_ACCESS, (1 << 12) | (0x3 << 8) | (0x1 << 3) | (1 << 2)
/* DRACR: XN bit 12, AP bits 10:8 (0b011 full access), TEX bits 5:3, S bit 2,
 * C bit 1, B bit 0. TEX 001 C B: normal, write-back write-allocate; TEX 001
 * with neither: normal, not cacheable; TEX 000 B: shareable device. */

/* Exception numbers cdcr_zynqmp_exception reports (startup.cpp). */
    .equ EXC_UNDEFINED, 1
    .equ EXC_SVC, 2
    .equ EXC_PREFETCH_ABORT, 3
    .equ EXC_DATA_ABORT, 4
    .equ EXC_IRQ, 6
    .equ EXC_FIQ, 7

/* The eight vectors, at address 0 (the linker script puts .vectors first and
 * the reset code clears SCTLR.V). No interrupt is enabled: QEMU 7.2 wires no
 * interrupt controller to the RPU, so every peripheral is polled; an IRQ or
 * FIQ arriving anyway is reported like a fault. */
    .section .vectors, "ax", %progbits
    .global cdcr_zynqmp_vector_table
cdcr_zynqmp_vector_table:
    ldr pc, =cdcr_zynqmp_reset
    ldr pc, =undefined_entry
    ldr pc, =svc_entry
    ldr pc, =prefetch_abort_entry
    ldr pc, =data_abort_entry
    nop                                 /* reserved */
    ldr pc, =irq_entry
    ldr pc, =fiq_entry
    .ltorg

    .text
    .type cdcr_zynqmp_reset, %function
    .global cdcr_zynqmp_reset
cdcr_zynqmp_reset:
    /* Vectors at 0 in ARM state; MPU and caches off until set up below. The
     * zcu102 releases the RPU with high vectors (SCTLR.V). */
    mrc p15, 0, r0, c1, c0, 0
    ldr r1, =(SCTLR_V | SCTLR_TE | SCTLR_M | SCTLR_C | SCTLR_I)
    bic r0, r0, r1
    mcr p15, 0, r0, c1, c0, 0
    isb

    /* Both R5F cores of the RPU in split mode start here (QEMU puts every
     * core it powers on at the ELF's entry): the first runs the program, the
     * second (second_core.hpp) its own stacks and entry. MPIDR's lowest
     * affinity field is the core's number: 0 and 1 on silicon, 4 and 5
     * under QEMU, which numbers the zcu102's cores after the four A53s; its
     * lowest bit tells them apart on both. r11 holds it to the end of the
     * reset code, r12 the offset of the core's stacks. In a program linked
     * without the second core's stacks, that core parks here, touching no
     * memory. */
    mrc p15, 0, r11, c0, c0, 5          /* MPIDR */
    and r11, r11, #1
    mov r12, #0
    cmp r11, #0
    beq 3f
    ldr r12, =__core_stacks_size__
    cmp r12, #0
    bne 3f
2:  wfi
    b 2b
3:

    /* One stack per exception mode, so a fault handler runs on a stack of its
     * own even when the program's stack is what went wrong; the program runs
     * in System mode on the main stack. Interrupts stay masked. Each core
     * has a set of its own (the linker script's .stack). */
    .macro mode_stack mode, top
    cps #\mode
    ldr sp, =\top
    add sp, sp, r12
    .endm
    mode_stack MODE_FIQ, __fiq_stack_top__
    mode_stack MODE_IRQ, __irq_stack_top__
    mode_stack MODE_ABT, __abort_stack_top__
    mode_stack MODE_UND, __undefined_stack_top__
    mode_stack MODE_SVC, __svc_stack_top__
    mode_stack MODE_SYS, __stack_top__

    /* The FPU before any C++ code: the compiler may use its registers
     * anywhere. Full access to CP10 and CP11 (CPACR), then FPEXC.EN. */
    mrc p15, 0, r0, c1, c0, 2
    orr r0, r0, #(0xF << 20)
    mcr p15, 0, r0, c1, c0, 2
    isb
    mov r0, #(1 << 30)
    vmsr fpexc, r0

    /* The MPU: three regions and nothing else, so a stray access anywhere
     * else (the OCM, the DDR above 2 GiB, the other peripherals) is a data
     * abort instead of a silent read or write. No background region. */
    .macro mpu_region number, base, access, size_enable
    mov r0, #\number
    mcr p15, 0, r0, c6, c2, 0           /* RGNR */
    ldr r0, =\base
    mcr p15, 0, r0, c6, c1, 0           /* DRBAR */
    ldr r0, =\access
    mcr p15, 0, r0, c6, c1, 4           /* DRACR */
    ldr r0, =\size_enable
    mcr p15, 0, r0, c6, c1, 2           /* DRSR */
    .endm
    mpu_region MPU_REGION_MEMORY, MPU_MEMORY_BASE, MPU_MEMORY_ACCESS, MPU_MEMORY_SIZE_ENABLE
    mpu_region MPU_REGION_PERIPHERALS, MPU_PERIPHERALS_BASE, MPU_PERIPHERALS_ACCESS, MPU_PERIPHERALS_SIZE_ENABLE
    mpu_region MPU_REGION_CORE_SHARED, __core_shared_start__, MPU_CORE_SHARED_ACCESS, MPU_CORE_SHARED_SIZE_ENABLE

    /* Both caches invalidated before they are enabled (their contents are
     * unknown after reset): the instruction cache at once, the data cache
     * set by set and way over the geometry CCSIDR reports. */
    mov r0, #0
    mcr p15, 0, r0, c7, c5, 0           /* ICIALLU */
    mcr p15, 2, r0, c0, c0, 0           /* CSSELR: level 1 data cache */
    isb
    mrc p15, 1, r1, c0, c0, 0           /* CCSIDR */
    and r2, r1, #7
    add r2, r2, #4                      /* log2(line bytes): the set's shift */
    ubfx r3, r1, #3, #10                /* ways - 1 */
    ubfx r4, r1, #13, #15               /* sets - 1 */
    clz r5, r3                          /* the way's shift */
1:  mov r6, r4                          /* each way ... */
2:  lsl r7, r3, r5                      /* ... each set */
    orr r7, r7, r6, lsl r2
    mcr p15, 0, r7, c7, c6, 2           /* DCISW */
    subs r6, r6, #1
    bge 2b
    subs r3, r3, #1
    bge 1b
    dsb

    /* MPU, data cache, instruction cache on. */
    mrc p15, 0, r0, c1, c0, 0
    ldr r1, =(SCTLR_M | SCTLR_C | SCTLR_I)
    orr r0, r0, r1
    dsb
    mcr p15, 0, r0, c1, c0, 0
    isb

    cmp r11, #0
    bne 4f
    bl cdcr_zynqmp_start                /* startup.cpp; does not return */
1:  b 1b
4:  bl cdcr_zynqmp_second_core_start    /* startup.cpp; does not return */
    b 1b
    .size cdcr_zynqmp_reset, . - cdcr_zynqmp_reset

/* Each entry reports its exception and the return address, and exits. */
undefined_entry:
    mov r0, #EXC_UNDEFINED
    mov r1, lr
    b cdcr_zynqmp_exception
svc_entry:
    mov r0, #EXC_SVC
    mov r1, lr
    b cdcr_zynqmp_exception
prefetch_abort_entry:
    mov r0, #EXC_PREFETCH_ABORT
    mov r1, lr
    b cdcr_zynqmp_exception
data_abort_entry:
    mov r0, #EXC_DATA_ABORT
    mov r1, lr
    b cdcr_zynqmp_exception
irq_entry:
    mov r0, #EXC_IRQ
    mov r1, lr
    b cdcr_zynqmp_exception
fiq_entry:
    mov r0, #EXC_FIQ
    mov r1, lr
    b cdcr_zynqmp_exception

/* int cdcr_zynqmp_semihosting_call(int operation, const void* argument):
 * ARM semihosting in ARM state (SVC 0x123456), which QEMU answers when run
 * with -semihosting-config enable=on. The board uses it for one thing: the
 * exit status QEMU ends with. Without QEMU's semihosting this SVC is taken as
 * an exception. */
    .global cdcr_zynqmp_semihosting_call
    .type cdcr_zynqmp_semihosting_call, %function
cdcr_zynqmp_semihosting_call:
    svc 0x123456
    bx lr
    .size cdcr_zynqmp_semihosting_call, . - cdcr_zynqmp_semihosting_call
