// The DOB kernel's Cortex-M4 backend (the program's layout and overflow notes in dob_kernel.hpp).
#include "dob_kernel.hpp"

#include <cstddef>
#include <cstdint>

#if !defined(__ARM_ARCH_7EM__) || !defined(__thumb2__)
#error "the cortex_m4 DOB backend is ARMv7E-M Thumb-2 assembly; build the portable one here"
#endif

namespace vibid::fixed {

// The program (see the header): one routine, vibid_fixed_dob_run, holding the frame
// loop, the output stages and one copy of the section code per (shift, feedback) pair, so the
// shifts, masks and rounding constants are immediates and the coefficient words stay few.
// Registers across the program: r0 the value passed along the path, r1 the program, r2 the state,
// lr the saturation count; per section r4:r5 the accumulator, r6..r11 the state, r3 and r12 the
// coefficients as loaded. Every block ends by loading the next block's first words and its code
// address into pc, so there is no loop counter and no branch but the frame loop's.
// The frame context on the stack: [0] program, [4] state, [8] output end, [12] input, [16] output,
// [20] [24] inputs 1 and 2 of the frame, [32] the sum of the output terms so far (64 bits).
asm(R"(
  .pushsection .text.vibid_fixed_dob_run,"ax",%progbits
  .syntax unified
  .thumb
  .align 2

  @ One section: acc = start + b2 x2 + a2 ~y2 + b0 x + b1 x1 + a1 ~y1 (+ 2 r1' - r2'), then
  @ ~y = ~(acc >> q), r' = the low q bits, the saturation test on the high word.
  .macro VIBID_DOB_SECTION q, feedback
  ldm r2, {r6-r11}
  smlal r4, r5, r3, r7
  smlal r4, r5, r12, r9
  .if \feedback
  ldmia r1!, {r3, r7, r9, r12}
  .else
  ldmia r1!, {r3, r7, r9}
  .endif
  smlal r4, r5, r3, r0
  smlal r4, r5, r7, r6
  smlal r4, r5, r9, r8
  .if \feedback
  .if \q == 31
  @ 2 r1' - r2' may not fit an int32 when q = 31: -r2' by the product with -1, 2 r1' < 2^32 added.
  smlal r4, r5, r12, r11
  adds r4, r4, r10, lsl #1
  adc r5, r5, #0
  .else
  @ q <= 30: 0 <= r' < 2^30, so 2 r1' - r2' fits an int32; multiplied by 1 to join the sum.
  rsb r11, r11, r10, lsl #1
  smlal r4, r5, r11, r12
  .endif
  .endif
  mvn r7, r5, lsl #(32 - \q)
  bic r7, r7, r4, lsr #\q
  add r9, r5, #(1 << (\q - 1))
  lsrs r9, r9, #\q
  ubfx r9, r4, #0, #\q
  itttt ne
  movne r7, #0x80000000
  eorne r7, r7, r5, asr #31
  movne r9, #(1 << (\q - 1))
  addne lr, lr, #1
  stmia r2!, {r0, r6, r7, r8, r9, r10}
  mvn r0, r7
  ldmia r1!, {r3, r4, r5, r12, pc}
  .endm

  @ A path's output term (y gain + 2^(p-1)) >> p in r4:r5, from r3 = gain, r4:r5 = 2^(p-1),
  @ r12 = p and the next word 2^(32 - p): lo >> p | hi << (32 - p) without a variable left shift.
  .macro VIBID_DOB_TERM
  ldr r6, [r1], #4
  smlal r4, r5, r0, r3
  lsr r4, r4, r12
  mla r4, r5, r6, r4
  asr r5, r5, r12
  .endm

  @ The last path's term, the sum saturated and stored, then the next frame of n inputs.
  .macro VIBID_DOB_LAST n
.Lvibid_dob_last_\n:
  VIBID_DOB_TERM
  .if \n > 1
  ldrd r7, r8, [sp, #32]
  adds r4, r4, r7
  adc r5, r5, r8
  .endif
  cmp r5, r4, asr #31
  ittt ne
  mvnne r4, #0x80000000
  eorne r4, r4, r5, asr #31
  addne lr, lr, #1
  ldm sp, {r1, r2, r6, r7, r8}
  str r4, [r8], #4
  cmp r8, r6
  beq .Lvibid_dob_done
.Lvibid_dob_frame_\n:
  .if \n == 1
  ldr r0, [r7], #4
  stm sp, {r1, r2, r6, r7, r8}
  .elseif \n == 2
  ldrd r0, r9, [r7], #8
  stm sp, {r1, r2, r6, r7, r8, r9}
  .else
  ldmia r7!, {r0, r9, r10}
  stm sp, {r1, r2, r6, r7, r8, r9, r10}
  .endif
  ldmia r1!, {r3, r4, r5, r12, pc}
  .endm

  .global vibid_fixed_dob_run
  .type vibid_fixed_dob_run, %function
  .thumb_func
vibid_fixed_dob_run:
  push {r4-r11, lr}
  sub sp, sp, #40
  mov r7, r1
  mov r8, r2
  mov r6, r3
  ldm r0, {r1, r2, r12}
  mov lr, #0
  bx r12
.Lvibid_dob_done:
  add sp, sp, #40
  mov r0, lr
  pop {r4-r11, pc}

.Lvibid_dob_first:
  VIBID_DOB_TERM
  strd r4, r5, [sp, #32]
  ldr r0, [sp, #20]
  ldmia r1!, {r3, r4, r5, r12, pc}

.Lvibid_dob_middle:
  VIBID_DOB_TERM
  ldrd r7, r8, [sp, #32]
  adds r4, r4, r7
  adc r5, r5, r8
  strd r4, r5, [sp, #32]
  ldr r0, [sp, #24]
  ldmia r1!, {r3, r4, r5, r12, pc}

  VIBID_DOB_LAST 1
  VIBID_DOB_LAST 2
  VIBID_DOB_LAST 3

  .irp q, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31
.Lvibid_dob_plain_\q:
  VIBID_DOB_SECTION \q, 0
.Lvibid_dob_feedback_\q:
  VIBID_DOB_SECTION \q, 1
  .endr
  .size vibid_fixed_dob_run, . - vibid_fixed_dob_run
  .popsection

  .pushsection .rodata.vibid_fixed_dob_code,"a",%progbits
  .align 2
  .global vibid_fixed_dob_code
vibid_fixed_dob_code:
  .irp q, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31
  .word .Lvibid_dob_plain_\q + 1
  .endr
  .irp q, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31
  .word .Lvibid_dob_feedback_\q + 1
  .endr
  .word .Lvibid_dob_first + 1, .Lvibid_dob_middle + 1
  .word .Lvibid_dob_last_1 + 1, .Lvibid_dob_last_2 + 1, .Lvibid_dob_last_3 + 1
  .word .Lvibid_dob_frame_1 + 1, .Lvibid_dob_frame_2 + 1, .Lvibid_dob_frame_3 + 1
  .size vibid_fixed_dob_code, . - vibid_fixed_dob_code
  .popsection
)");

extern "C" {
// kernel: {program, state, frame loop entry}; frames of input_count inputs from `input` until
// `output` reaches `output_end`. Returns the saturations.
std::uint32_t vibid_fixed_dob_run(const std::uintptr_t* kernel, const std::int32_t* input,
                                  std::int32_t* output, std::int32_t* output_end);
extern const std::uint32_t vibid_fixed_dob_code[];
}

namespace {

// Indices into vibid_fixed_dob_code.
constexpr std::size_t kPlainSection = 0;      // + q - 16
constexpr std::size_t kFeedbackSection = 16;  // + q - 16
constexpr std::size_t kFirstStage = 32;
constexpr std::size_t kMiddleStage = 33;
constexpr std::size_t kLastStage = 33;  // + input_count
constexpr std::size_t kFrameLoop = 36;  // + input_count

}  // namespace

void DobKernel::Load(const FilterDescription& description) {
  program_ = {};
  const std::size_t n_in = description.input_count;
  std::size_t w = 0;
  const auto put = [&](std::int64_t v) { program_[w++] = static_cast<std::uint32_t>(v); };
  for (std::size_t i = 0; i < n_in; ++i) {
    const Path& p = description.paths[i];
    for (std::size_t k = 0; k < p.section_count; ++k) {
      const Section& s = p.sections[k];
      const bool feedback = s.feedback == ErrorFeedback::kSecondOrder;
      const std::int32_t q = 31 - s.shift;
      const std::int64_t half = std::int64_t{1} << (q - 1);
      // -a y = a ~y + a, and 2 r1 - r2 = 2 r1' - r2' - half (r' = r + half): see the header.
      const std::int64_t start = half + s.a1 + s.a2 - (feedback ? half : 0);
      put(s.b2);
      put(start);
      put(start >> 32);
      put(s.a2);
      program_[w++] = vibid_fixed_dob_code[(feedback ? kFeedbackSection : kPlainSection) +
                                           static_cast<std::size_t>(q - 16)];
      put(s.b0);
      put(s.b1);
      put(s.a1);
      if (feedback) put(q == 31 ? -1 : 1);
    }
    const std::int32_t shift = 31 - p.output_shift;
    put(p.output_gain);
    put(std::int64_t{1} << (shift - 1));
    put(0);
    put(shift);
    program_[w++] = vibid_fixed_dob_code[i + 1 == n_in ? kLastStage + n_in
                                                       : (i == 0 ? kFirstStage : kMiddleStage)];
    put(std::int64_t{1} << (32 - shift));
  }
  frame_start_ = vibid_fixed_dob_code[kFrameLoop + n_in];
  Reset(description);
}

void DobKernel::Reset(const FilterDescription& description) {
  // At rest: x = y = 0 (so ~y = -1) and remainders 0 (so r' = half).
  state_ = {};
  std::size_t w = 0;
  for (std::size_t i = 0; i < description.input_count; ++i) {
    const Path& p = description.paths[i];
    for (std::size_t k = 0; k < p.section_count; ++k) {
      const std::int32_t half = std::int32_t{1} << (30 - p.sections[k].shift);
      state_[w + 2] = state_[w + 3] = -1;
      state_[w + 4] = state_[w + 5] = half;
      w += 6;
    }
  }
}

std::uint32_t DobKernel::Run(const std::int32_t* inputs, std::int32_t* output, std::size_t frames) {
  const std::uintptr_t kernel[3] = {reinterpret_cast<std::uintptr_t>(program_.data()),
                                    reinterpret_cast<std::uintptr_t>(state_.data()), frame_start_};
  return vibid_fixed_dob_run(kernel, inputs, output, output + frames);
}

}  // namespace vibid::fixed
