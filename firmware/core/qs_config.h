/* Build-time configuration of the firmware core. Every value can be
 * overridden with -D; the native emulator also narrows some at run time
 * (qs_core_configure). */
#ifndef QS_CONFIG_H
#define QS_CONFIG_H

/* Axes the engine can drive (storage and per-tick work), 1 to 4. */
#ifndef QS_AXIS_COUNT
#define QS_AXIS_COUNT 4
#endif
#if QS_AXIS_COUNT < 1 || QS_AXIS_COUNT > 4
#error "QS_AXIS_COUNT must be 1 to 4"
#endif

/* Segment slots in the queue, 1 to 127 (u8 indices run over twice this). */
#ifndef QS_QUEUE_CAPACITY
#define QS_QUEUE_CAPACITY 16
#endif
#if QS_QUEUE_CAPACITY < 1 || QS_QUEUE_CAPACITY > 127
#error "QS_QUEUE_CAPACITY must be 1 to 127"
#endif

/* Step ticks per second (reported to the host; the target sets its timer). */
#ifndef QS_TICK_HZ
#define QS_TICK_HZ 50000UL
#endif

/* SEGMENTS frames (chained quadratic records) taken: 1, or 0 where flash
 * is short. The host sends an AVR board one SEGMENT a frame, which it
 * takes faster (protocol/frame_choice.py), so the Uno's build leaves the
 * reader out (capability bit SEGMENTS clear): 1.2 KB of its flash. */
#ifndef QS_QUADRATIC_RUNS
#define QS_QUADRATIC_RUNS 1
#endif

/* Cubic (jerk-limited) segments taken: 1, or 0 in a build that leaves them
 * out for the room RASTER needs (the Uno's laser build, docs/AVR.md):
 * capability bits CUBIC_SEGMENTS and CUBIC_RUNS clear, and the host then
 * refuses a configuration with max_jerk. */
#ifndef QS_CUBIC
#define QS_CUBIC 1
#endif

/* Pixel powers the RASTER ring holds (IDENTIFY_REPLY's raster_ring,
 * qs_raster.h); 0 builds no RASTER (the capability bit is then clear and
 * the type unknown). At most 1024 (a slot's 10-bit index), a power of two.
 * The Uno's laser build keeps 128; the Uno's own, none. */
#ifndef QS_RASTER_BYTES
#define QS_RASTER_BYTES (QS_QUEUE_CAPACITY < 16 ? 0 : 1024)
#endif

/* Board code reported by IDENTIFY: 0 emulator, 1 ATmega328P, 2 ATmega2560. */
#ifndef QS_BOARD
#define QS_BOARD 0
#endif

#define QS_FW_MAJOR 0
#define QS_FW_MINOR 1
#define QS_FW_PATCH 0

/* The tick path must compile into the timer interrupt without calls: a call
 * makes avr-gcc save every call-clobbered register in the ISR prologue.
 * QS_NOINLINE keeps rare, large work out of a hot caller, whose registers
 * (and the stack frame they spill to) it would otherwise inflate. */
#if defined(__GNUC__)
#define QS_ALWAYS_INLINE __attribute__((always_inline)) inline
#define QS_NOINLINE __attribute__((noinline))
#define QS_COMPILER_BARRIER() __asm__ __volatile__("" ::: "memory")
#define QS_UNLIKELY(x) __builtin_expect(!!(x), 0)
#else
#define QS_ALWAYS_INLINE inline
#define QS_NOINLINE
#define QS_COMPILER_BARRIER() ((void)0)
#define QS_UNLIKELY(x) (x)
#endif

#endif
