// The DOB kernel's Cortex-M4 backend (the program's layout and overflow notes in dob_kernel.hpp).
#include "dob_kernel.hpp"

#include <cstddef>
#include <cstdint>
#include <limits>

#if !defined(__ARM_ARCH_7EM__) || !defined(__thumb2__)
#error "the cortex_m4 DOB backend is ARMv7E-M Thumb-2 assembly; build the portable one here"
#endif

namespace vibid::fixed {

// The program (see the header): one routine, vibid_fixed_dob_run, holding the frame loops, the
// output stages and the section code, one copy per (position parity, q, feedback) and for the
// q = 31 sections with a1 = -2^31, so the shifts, the mask and the railed remainder are
// immediates.
// Registers across the program: r1 the program, r2 the state; per section r4:r5 the accumulator.
// An even section (E) takes x in r0, loads its state {x1 x2 y1 y2 r1' r2'} into r6..r11 and
// leaves y in r7; an odd one (O) takes x in r7, loads {y1 y2 x1 x2 r1' r2'} into r3, r6, r8..r11
// and leaves y in r0. Each block ends with the LDM that loads the next block's first words and
// its code address into pc: {r0, r4, r5, r6, r12} (next block odd: an O section or the stage
// after an E one) or {r3, r4, r5, r6, r12} (next block even), so there is no loop counter and no
// branch on the way but the frame loop's and the saturation tests' (not taken). (A Thumb LDM may
// not load both lr and pc, so the feedback weights come with a section's second load, into lr.)
// The frame context on the stack: [0] program, [4] state, [8] output end, [12] input, [16] output,
// [20] [24] inputs 1 and 2 of the frame, [32] the sum of the output terms so far (64 bits),
// [40] the saturation count.
asm(R"(
  .pushsection .text.vibid_fixed_dob_run,"ax",%progbits
  .syntax unified
  .thumb
  .align 2

  @ One section at position parity \odd: acc = start + b2 x2 + na2 y2 + b0 x + b1 x1 + na1 y1
  @ (+ 2 r1' - r2'), y = acc >> q from the two halves, r' = its low q bits, the state stored,
  @ then the saturation test: hi must be y >> (32 - q) (arithmetic), else the stub rails y.
  @ \amin: na1 is -2^31 standing for +2^31 (a1 = -2^31), so y1 2^32 is added to the high word.
  .macro VIBID_DOB_SECTION odd, q, feedback, amin
  .if \odd == 0
  ldm r2, {r6-r11}
  smlal r4, r5, r3, r7
  smlal r4, r5, r12, r9
  .if \feedback
  ldmia r1!, {r3, r7, r9, r12, lr}
  .else
  ldmia r1!, {r3, r7, r9}
  .endif
  smlal r4, r5, r3, r0
  smlal r4, r5, r7, r6
  smlal r4, r5, r9, r8
  .if \amin
  add r5, r5, r8
  .endif
  .if \feedback
  umlal r4, r5, r12, r10
  smlal r4, r5, lr, r11
  .endif
  lsl r7, r5, #(32 - \q)
  orr r7, r7, r4, lsr #\q
  ubfx r9, r4, #0, #\q
  stmia r2!, {r0, r6, r7, r8, r9, r10}
  cmp r5, r7, asr #(32 - \q)
  bne .Lvibid_dob_sat\@
  ldmia r1!, {r0, r4, r5, r6, r12, pc}
.Lvibid_dob_sat\@:
  mvn r7, #0x80000000
  eor r7, r7, r5, asr #31
  mov r3, #(1 << (\q - 1))
  str r7, [r2, #-16]
  str r3, [r2, #-8]
  ldr r3, [sp, #40]
  add r3, r3, #1
  str r3, [sp, #40]
  ldmia r1!, {r0, r4, r5, r6, r12, pc}
  .else
  ldm r2, {r3, r6, r8, r9, r10, r11}
  smlal r4, r5, r0, r9
  smlal r4, r5, r12, r6
  .if \feedback
  ldmia r1!, {r0, r6, r9, r12, lr}
  .else
  ldmia r1!, {r0, r6, r9}
  .endif
  smlal r4, r5, r0, r7
  smlal r4, r5, r6, r8
  smlal r4, r5, r9, r3
  .if \amin
  add r5, r5, r3
  .endif
  .if \feedback
  umlal r4, r5, r12, r10
  smlal r4, r5, lr, r11
  .endif
  lsl r0, r5, #(32 - \q)
  orr r0, r0, r4, lsr #\q
  ubfx r9, r4, #0, #\q
  stmia r2!, {r0, r3, r7, r8, r9, r10}
  cmp r5, r0, asr #(32 - \q)
  bne .Lvibid_dob_sat\@
  ldmia r1!, {r3, r4, r5, r6, r12, pc}
.Lvibid_dob_sat\@:
  mvn r0, #0x80000000
  eor r0, r0, r5, asr #31
  mov r3, #(1 << (\q - 1))
  str r0, [r2, #-24]
  str r3, [r2, #-8]
  ldr r3, [sp, #40]
  add r3, r3, #1
  str r3, [sp, #40]
  ldmia r1!, {r3, r4, r5, r6, r12, pc}
  .endif
  .endm

  @ A path's output term (y gain + 2^(p-1)) >> p into r4:r5, from r4:r5 = 2^(p-1), r6 = 2^(32-p),
  @ r12 = p and y in r0 with the gain in r3 (after an odd section or none) or y in r7 with the
  @ gain in r0 (after an even one): lo >> p | hi << (32 - p) without a variable left shift.
  .macro VIBID_DOB_TERM after_even
  .if \after_even
  smlal r4, r5, r7, r0
  .else
  smlal r4, r5, r0, r3
  .endif
  lsr r4, r4, r12
  mla r4, r5, r6, r4
  asr r5, r5, r12
  .endm

  @ The first and the middle paths' stages: the term joins the frame's sum, the next path's input
  @ goes to r0 and the next block (an even section or a stage after none) is loaded.
  .macro VIBID_DOB_FIRST after_even
.Lvibid_dob_first_\after_even:
  VIBID_DOB_TERM \after_even
  strd r4, r5, [sp, #32]
  ldr r0, [sp, #20]
  ldmia r1!, {r3, r4, r5, r6, r12, pc}
  .endm

  .macro VIBID_DOB_MIDDLE after_even
.Lvibid_dob_middle_\after_even:
  VIBID_DOB_TERM \after_even
  ldrd r6, r7, [sp, #32]
  adds r4, r4, r6
  adc r5, r5, r7
  strd r4, r5, [sp, #32]
  ldr r0, [sp, #24]
  ldmia r1!, {r3, r4, r5, r6, r12, pc}
  .endm

  @ The last path's stage for n inputs: the sum saturated (the stub rails it) and stored, then
  @ the next frame: its inputs read, the context saved and the first block loaded. The frame loop
  @ entry for n inputs is the one after an even section.
  .macro VIBID_DOB_LAST after_even, n
.Lvibid_dob_last_\after_even\()_\n:
  VIBID_DOB_TERM \after_even
  .if \n > 1
  ldrd r6, r7, [sp, #32]
  adds r4, r4, r6
  adc r5, r5, r7
  .endif
  cmp r5, r4, asr #31
  bne .Lvibid_dob_rail\@
.Lvibid_dob_railed\@:
  ldm sp, {r1, r2, r6, r7, r8}
  str r4, [r8], #4
  cmp r8, r6
  beq .Lvibid_dob_done
  .if \after_even
.Lvibid_dob_frame_\n:
  .endif
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
  ldmia r1!, {r3, r4, r5, r6, r12, pc}
.Lvibid_dob_rail\@:
  mvn r4, #0x80000000
  eor r4, r4, r5, asr #31
  ldr r6, [sp, #40]
  add r6, r6, #1
  str r6, [sp, #40]
  b .Lvibid_dob_railed\@
  .endm

  .global vibid_fixed_dob_run
  .type vibid_fixed_dob_run, %function
  .thumb_func
vibid_fixed_dob_run:
  push {r4-r11, lr}
  sub sp, sp, #48
  mov r7, r1
  mov r8, r2
  mov r6, r3
  mov r4, #0
  str r4, [sp, #40]
  ldm r0, {r1, r2, r12}
  bx r12
.Lvibid_dob_done:
  ldr r0, [sp, #40]
  add sp, sp, #48
  pop {r4-r11, pc}

  .irp e, 0, 1
  VIBID_DOB_FIRST \e
  VIBID_DOB_MIDDLE \e
  VIBID_DOB_LAST \e, 1
  VIBID_DOB_LAST \e, 2
  VIBID_DOB_LAST \e, 3
  .endr

  @ Every section kind, labelled by parity, feedback and q (the code table below lists them).
  .macro VIBID_DOB_SECTION_KIND odd, feedback, q
.Lvibid_dob_section_\odd\()_\feedback\()_\q:
  VIBID_DOB_SECTION \odd, \q, \feedback, 0
  .endm
  .macro VIBID_DOB_AMIN_KIND odd, feedback
.Lvibid_dob_amin_\odd\()_\feedback:
  VIBID_DOB_SECTION \odd, 31, \feedback, 1
  .endm
  .irp odd, 0, 1
  .irp feedback, 0, 1
  .irp q, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31
  VIBID_DOB_SECTION_KIND \odd, \feedback, \q
  .endr
  VIBID_DOB_AMIN_KIND \odd, \feedback
  .endr
  .endr
  .size vibid_fixed_dob_run, . - vibid_fixed_dob_run
  .popsection

  .pushsection .rodata.vibid_fixed_dob_code,"a",%progbits
  .align 2
  .global vibid_fixed_dob_code
vibid_fixed_dob_code:
  .macro VIBID_DOB_SECTION_WORD odd, feedback, q
  .word .Lvibid_dob_section_\odd\()_\feedback\()_\q + 1
  .endm
  .macro VIBID_DOB_AMIN_WORD odd, feedback
  .word .Lvibid_dob_amin_\odd\()_\feedback + 1
  .endm
  .macro VIBID_DOB_STAGE_WORDS e
  .word .Lvibid_dob_first_\e + 1, .Lvibid_dob_middle_\e + 1
  .word .Lvibid_dob_last_\e\()_1 + 1, .Lvibid_dob_last_\e\()_2 + 1, .Lvibid_dob_last_\e\()_3 + 1
  .endm
  .irp odd, 0, 1
  .irp feedback, 0, 1
  .irp q, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31
  VIBID_DOB_SECTION_WORD \odd, \feedback, \q
  .endr
  .endr
  .endr
  .irp odd, 0, 1
  .irp feedback, 0, 1
  VIBID_DOB_AMIN_WORD \odd, \feedback
  .endr
  .endr
  VIBID_DOB_STAGE_WORDS 0
  VIBID_DOB_STAGE_WORDS 1
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
constexpr std::size_t SectionCode(std::size_t odd, bool feedback, std::int32_t q) {
  return odd * 32 + (feedback ? 16 : 0) + static_cast<std::size_t>(q - 16);
}
constexpr std::size_t AminCode(std::size_t odd, bool feedback) {
  return 64 + odd * 2 + (feedback ? 1 : 0);
}
// Stage kinds: 0 first, 1 middle, 1 + n the last of n inputs.
constexpr std::size_t StageCode(bool after_even, std::size_t kind) {
  return 68 + (after_even ? 5 : 0) + kind;
}
constexpr std::size_t FrameCode(std::size_t n_in) { return 78 + n_in - 1; }

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
      // acc + 2^(q-1) with -a y = (-a) y and 2 r1 - r2 = 2 r1' - r2' - 2^(q-1): see the header.
      const std::int64_t start = feedback ? 0 : std::int64_t{1} << (q - 1);
      // -a1 does not fit an int32 for a1 = -2^31 (only at q = 31, ValidateDescription's
      // stability bound): its bits stand for +2^31 and the amin code adds the difference.
      const bool amin = s.a1 == std::numeric_limits<std::int32_t>::min();
      put(s.b2);
      put(start);
      put(start >> 32);
      put(0);  // the r6 slot: a stage's 2^(32-p), overwritten by a section's state
      put(-std::int64_t{s.a2});
      program_[w++] =
          vibid_fixed_dob_code[amin ? AminCode(k % 2, feedback) : SectionCode(k % 2, feedback, q)];
      put(s.b0);
      put(s.b1);
      put(-std::int64_t{s.a1});
      if (feedback) {
        put(2);   // times r1' (unsigned: r1' < 2^31, 2 r1' < 2^32)
        put(-1);  // times r2'
      }
    }
    const std::int32_t shift = 31 - p.output_shift;
    const bool after_even = p.section_count % 2 == 1;
    put(p.output_gain);
    put(std::int64_t{1} << (shift - 1));
    put(0);
    put(std::int64_t{1} << (32 - shift));
    put(shift);
    program_[w++] =
        vibid_fixed_dob_code[StageCode(after_even, i + 1 == n_in ? 1 + n_in : (i == 0 ? 0 : 1))];
  }
  frame_start_ = vibid_fixed_dob_code[FrameCode(n_in)];
  Reset(description);
}

void DobKernel::Reset(const FilterDescription& description) {
  // At rest: x = y = 0 and remainders 0 (so r' = 2^(q-1)), in both state layouts.
  state_ = {};
  std::size_t w = 0;
  for (std::size_t i = 0; i < description.input_count; ++i) {
    const Path& p = description.paths[i];
    for (std::size_t k = 0; k < p.section_count; ++k) {
      const std::int32_t half = std::int32_t{1} << (30 - p.sections[k].shift);
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
