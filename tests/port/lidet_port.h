/* SPDX-License-Identifier: MIT */
/* A test port (tests/port/test_port.c): its assert hook counts the checks the library makes, and the
 * workspace goes to a section of its own, found through the linker's __start_/__stop_ symbols. */
#ifndef LIDET_PORT_H
#define LIDET_PORT_H

extern unsigned long lidet_port_test_checks;
extern unsigned long lidet_port_test_failures;
#define LIDET_ASSERT(c) ((void)(++lidet_port_test_checks, (c) ? 0 : (++lidet_port_test_failures, 0)))

#define LIDET_WORKSPACE_SECTION __attribute__((section("lidet_ws")))

#endif
