//! The control transfers in Thumb-2 code (ARMv7-M), decoded from the instruction encodings of
//! the Arm Architecture Reference Manual (ARM DDI 0403, §A5 and §A7.7): enough to build a call
//! graph, not a disassembler.
//!
//! Every instruction is 16 or 32 bits; it is 32 bits when its first halfword's top five bits are
//! 0b11101, 0b11110 or 0b11111. The transfers that matter:
//!
//! | instruction | encoding | what it is here |
//! |---|---|---|
//! | `BL label` | T1, 32-bit | [`Transfer::Call`] |
//! | `B.W label` | T4, 32-bit | [`Transfer::Jump`] (a tail call when it leaves the function) |
//! | `B<c>.W label` | T3, 32-bit | [`Transfer::Jump`] |
//! | `B label`, `B<c> label` | T2, T1, 16-bit | [`Transfer::Jump`] |
//! | `BLX Rm` | T1, 16-bit | [`Transfer::Indirect`] (a call through a register) |
//! | `BX Rm`, Rm ≠ LR; `MOV PC, Rm`; `LDR PC, [Rn…]`, Rn ≠ SP | | [`Transfer::Indirect`] |
//!
//! Returns (`BX LR`, `POP {…, PC}`, `LDR PC, [SP], #4`), `CBZ`/`CBNZ` and `TBB`/`TBH` stay inside
//! the function and are not reported.

/// One control transfer out of straight-line code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transfer {
    /// `BL`: a call to the address.
    Call(u64),
    /// A branch to the address: within the function, or a tail call if it leaves it.
    Jump(u64),
    /// A branch or call through a register or memory: its target is not in the code.
    Indirect,
}

/// Whether the halfword starts a 32-bit instruction.
fn is_32bit(hw1: u16) -> bool {
    matches!(hw1 >> 11, 0b11101..=0b11111)
}

/// Sign-extends the low `bits` bits of `v`.
fn sign_extend(v: u32, bits: u32) -> i64 {
    let shift = 32 - bits;
    ((v << shift) as i32 >> shift) as i64
}

/// The transfer of one 32-bit instruction at `addr`, if it is one.
fn decode_32(hw1: u16, hw2: u16, addr: u64) -> Option<Transfer> {
    let (h1, h2) = (hw1 as u32, hw2 as u32);
    let pc = addr as i64 + 4;
    // Branches and miscellaneous control: hw1 = 11110 xxxxx xxxxxx, hw2 = 1x xxx…
    if h1 & 0xf800 == 0xf000 && h2 & 0x8000 != 0 {
        let s = (h1 >> 10) & 1;
        let (j1, j2) = ((h2 >> 13) & 1, (h2 >> 11) & 1);
        let imm11 = h2 & 0x7ff;
        let op = (h2 >> 12) & 0b101; // bits 14 and 12
        return match op {
            // BL (T1, bit 14 and bit 12 set) and B.W (T4, bit 12 set): 25-bit offset.
            0b101 | 0b001 => {
                let (i1, i2) = ((!(j1 ^ s)) & 1, (!(j2 ^ s)) & 1);
                let imm = (s << 24) | (i1 << 23) | (i2 << 22) | ((h1 & 0x3ff) << 12) | (imm11 << 1);
                let target = (pc + sign_extend(imm, 25)) as u64;
                Some(if op == 0b101 {
                    Transfer::Call(target)
                } else {
                    Transfer::Jump(target)
                })
            }
            // B<c>.W (T3) unless the condition field is 111x (then it is MSR, MRS, hints…).
            0b000 if (h1 >> 6) & 0xf < 0b1110 => {
                let imm = (s << 20) | (j2 << 19) | (j1 << 18) | ((h1 & 0x3f) << 12) | (imm11 << 1);
                Some(Transfer::Jump((pc + sign_extend(imm, 21)) as u64))
            }
            // BLX (immediate) would switch to the Arm state, which M-profile cores do not have.
            0b100 => Some(Transfer::Indirect),
            _ => None,
        };
    }
    // LDR PC, [Rn, …] (LDR.W T3 / T4): Rt = PC is a branch through memory, unless it pops
    // the return address (Rn = SP).
    let rt = (h2 >> 12) & 0xf;
    let rn = h1 & 0xf;
    if (h1 & 0xfff0 == 0xf8d0 || h1 & 0xfff0 == 0xf850) && rt == 15 && rn != 13 {
        return Some(Transfer::Indirect);
    }
    None
}

/// The transfer of one 16-bit instruction at `addr`, if it is one.
fn decode_16(hw: u16, addr: u64) -> Option<Transfer> {
    let h = hw as u32;
    let pc = addr as i64 + 4;
    // B<c> (T1): 1101 cond imm8, cond < 1110 (1110 is UDF, 1111 SVC).
    if h & 0xf000 == 0xd000 && (h >> 8) & 0xf < 0b1110 {
        return Some(Transfer::Jump(
            (pc + sign_extend((h & 0xff) << 1, 9)) as u64,
        ));
    }
    // B (T2): 11100 imm11.
    if h & 0xf800 == 0xe000 {
        return Some(Transfer::Jump(
            (pc + sign_extend((h & 0x7ff) << 1, 12)) as u64,
        ));
    }
    // BLX Rm: 0100 0111 1 Rm 000.
    if h & 0xff87 == 0x4780 {
        return Some(Transfer::Indirect);
    }
    // BX Rm: 0100 0111 0 Rm 000; BX LR is a return.
    if h & 0xff87 == 0x4700 && (h >> 3) & 0xf != 14 {
        return Some(Transfer::Indirect);
    }
    // MOV PC, Rm: 0100 0110 D Rm Rd with D:Rd = 15.
    if h & 0xff87 == 0x4687 {
        return Some(Transfer::Indirect);
    }
    None
}

/// The transfers in `code`, which starts at address `base` (a halfword-aligned run of Thumb
/// instructions, no data), with the address of each instruction.
pub fn transfers(code: &[u8], base: u64) -> Vec<(u64, Transfer)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i + 2 <= code.len() {
        let hw1 = u16::from_le_bytes([code[i], code[i + 1]]);
        let addr = base + i as u64;
        if is_32bit(hw1) {
            if i + 4 > code.len() {
                break;
            }
            let hw2 = u16::from_le_bytes([code[i + 2], code[i + 3]]);
            if let Some(t) = decode_32(hw1, hw2, addr) {
                out.push((addr, t));
            }
            i += 4;
        } else {
            if let Some(t) = decode_16(hw1, addr) {
                out.push((addr, t));
            }
            i += 2;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Little-endian bytes of halfwords.
    fn bytes(halfwords: &[u16]) -> Vec<u8> {
        halfwords.iter().flat_map(|h| h.to_le_bytes()).collect()
    }

    // Encodings worked out by hand from ARM DDI 0403E §A7.7 (BL T1, B T1–T4, BLX, BX) and
    // cross-checked with `llvm-objdump -d --triple=thumbv7em` (LLVM 14).

    #[test]
    fn bl_forward_and_backward() {
        // `bl #+0x1c` at 0x1000: offset 0x1c → S=0, imm10=0, J1=J2=1, imm11=0xe.
        assert_eq!(
            transfers(&bytes(&[0xf000, 0xf80e]), 0x1000),
            [(0x1000, Transfer::Call(0x1020))]
        );
        // `bl .` (a call to itself): offset −4 → S=1, imm10=0x3ff, J1=J2=1, imm11=0x7fe.
        assert_eq!(
            transfers(&bytes(&[0xf7ff, 0xfffe]), 0x2000),
            [(0x2000, Transfer::Call(0x2000))]
        );
        // A far call: +0x12_3456 → S=0, I1=0, I2=0 (J1=J2=1), imm10=0x123, imm11=0x22b.
        assert_eq!(
            transfers(&bytes(&[0xf123, 0xfa2b]), 0),
            [(0, Transfer::Call(0x12_345a))]
        );
    }

    #[test]
    fn wide_and_narrow_branches_and_register_transfers() {
        let code = bytes(&[
            0xf000, 0xb80e, // 0x00 b.w #+0x1c → 0x20
            0xd1fc, // 0x04 bne #−8 → 0x00
            0xe7fe, // 0x06 b . → 0x06
            0xf43f,
            0xaffe, // 0x08 beq.w #−4 → 0x08 (S=1, cond=0, imm6=0x3f, J1=J2=1, imm11=0x7fe)
            0x4798, // 0x0c blx r3
            0x4770, // 0x0e bx lr (return: not reported)
            0x4718, // 0x10 bx r3
            0xbd10, // 0x12 pop {r4, pc} (return)
            0xf3ef, 0x8010, // 0x14 mrs r0, primask (cond field 1111: not a branch)
            0xf8d3, 0xf000, // 0x18 ldr.w pc, [r3]
            0xf85d, 0xfb04, // 0x1c ldr pc, [sp], #4 (return)
        ]);
        assert_eq!(
            transfers(&code, 0),
            [
                (0x00, Transfer::Jump(0x20)),
                (0x04, Transfer::Jump(0x00)),
                (0x06, Transfer::Jump(0x06)),
                (0x08, Transfer::Jump(0x08)),
                (0x0c, Transfer::Indirect),
                (0x10, Transfer::Indirect),
                (0x18, Transfer::Indirect),
            ]
        );
    }

    #[test]
    fn a_32_bit_instruction_is_not_read_as_two_16_bit_ones() {
        // `add.w r0, r1, #0xe000` would start with 0xf501; its second halfword 0xe0.. alone
        // would be a `b`. Also `vmul.f32` (0xee20 0x0a01). Neither is a transfer.
        let code = bytes(&[0xf501, 0x4060, 0xee20, 0x0a01, 0xf000, 0xf800]);
        assert_eq!(transfers(&code, 0), [(8, Transfer::Call(12))]);
    }
}
