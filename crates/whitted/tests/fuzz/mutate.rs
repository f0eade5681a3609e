//! Mutations of an input, at the level of bytes (flips, truncation,
//! splices, duplication) and, for text, of tokens and lines (numbers
//! replaced by extremes, words and lines dropped, duplicated, swapped, and
//! words of the format inserted).

use whitted::math::random::Rng;

/// Inputs are cut to this length, so every case stays fast; what only a
/// large input can show (quadratic work) is tested apart.
pub const MAX_INPUT: usize = 64 << 10;

/// Numbers that break arithmetic, sizes and indices. Some are not valid in
/// every format, which is also worth trying.
const EXTREMES: &[&str] = &[
    "0",
    "-0",
    "0.0",
    "-0.0",
    "1",
    "-1",
    "2",
    "3",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e-320",
    "-1e-320",
    "1e-300",
    "nan",
    "-nan",
    "NaN",
    "inf",
    "-inf",
    "+inf",
    "1e400",
    "-1e400",
    "65535",
    "65536",
    "1000000000",
    "2147483647",
    "-2147483648",
    "4294967295",
    "4294967296",
    "9223372036854775807",
    "-9223372036854775808",
    "18446744073709551616",
    "99999999999999999999999999",
    "0x7fffffff",
    "1_000",
    "1e9",
    "180",
    "-90",
    "360",
];

/// Bytes that mean something in one of the formats.
const SPECIAL_BYTES: &[u8] = b"\0\n\r\t #[]{}\"'=,./\\-+e";

/// A mutator of the inputs of one format.
pub struct Mutator<'a> {
    /// The case's randomness.
    pub rng: Rng,
    /// Whether the input is text (token and line mutations apply).
    text: bool,
    /// Other inputs of the format, to splice from.
    corpus: &'a [Vec<u8>],
    /// Words of the format, to insert.
    vocabulary: &'a [String],
}

impl<'a> Mutator<'a> {
    /// A mutator drawing from `rng`.
    pub fn new(rng: Rng, text: bool, corpus: &'a [Vec<u8>], vocabulary: &'a [String]) -> Self {
        Self {
            rng,
            text,
            corpus,
            vocabulary,
        }
    }

    /// A uniform index below `n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        self.rng.below(n as u32) as usize
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.rng.uniform() < p
    }

    /// Applies one to four mutations to `input`, then cuts it to
    /// [`MAX_INPUT`]. Text has, two times in five, only one to three of its
    /// numbers replaced: such inputs mostly still parse, so the hostile
    /// numbers reach the renderer.
    pub fn mutate(&mut self, input: &mut Vec<u8>) {
        if self.text && self.chance(0.4) {
            for _ in 0..1 + self.below(3) {
                self.replace_number(input);
            }
            return;
        }
        let rounds = 1 + self.below(4);
        for _ in 0..rounds {
            if self.text && self.chance(0.7) {
                self.mutate_tokens(input);
            } else {
                self.mutate_bytes(input);
            }
        }
        input.truncate(MAX_INPUT);
    }

    /// One byte-level mutation.
    fn mutate_bytes(&mut self, input: &mut Vec<u8>) {
        let len = input.len();
        match self.below(8) {
            0 if len > 0 => {
                let i = self.below(len);
                input[i] ^= 1 << self.below(8);
            }
            1 if len > 0 => {
                let i = self.below(len);
                input[i] = if self.chance(0.5) {
                    SPECIAL_BYTES[self.below(SPECIAL_BYTES.len())]
                } else {
                    self.rng.next_u32() as u8
                };
            }
            2 => {
                let i = self.below(len + 1);
                let byte = SPECIAL_BYTES[self.below(SPECIAL_BYTES.len())];
                input.insert(i, byte);
            }
            3 if len > 0 => {
                let (start, end) = self.range(len);
                input.drain(start..end);
            }
            4 => input.truncate(self.below(len + 1)),
            5 if len > 0 => {
                let (start, end) = self.range(len);
                let copies = if self.chance(0.1) {
                    1 + self.below(64)
                } else {
                    1
                };
                let piece = input[start..end].repeat(copies);
                let at = self.below(len + 1);
                input.splice(at..at, piece);
            }
            6 if !self.corpus.is_empty() => {
                let other = &self.corpus[self.below(self.corpus.len())];
                if !other.is_empty() {
                    let (start, end) = self.range(other.len());
                    let at = self.below(len + 1);
                    let cut = if self.chance(0.5) { len } else { at };
                    input.truncate(cut.max(at));
                    input.splice(at..at, other[start..end].iter().copied());
                }
            }
            _ => {
                // Four bytes somewhere set to an extreme 32-bit pattern
                // (binary formats store counts and floats this way).
                if len >= 4 {
                    let i = self.below(len - 3);
                    let patterns: [u32; 6] = [
                        0,
                        u32::MAX,
                        0x7fc0_0000,
                        0x7f80_0000,
                        0xff80_0000,
                        0x8000_0000,
                    ];
                    let value = patterns[self.below(patterns.len())];
                    input[i..i + 4].copy_from_slice(&value.to_le_bytes());
                }
            }
        }
    }

    /// A non-empty byte range of a `len`-byte input, short more often than
    /// long.
    fn range(&mut self, len: usize) -> (usize, usize) {
        let start = self.below(len);
        let longest = len - start;
        let size = if self.chance(0.8) {
            1 + self.below(longest.min(16))
        } else {
            1 + self.below(longest)
        };
        (start, start + size)
    }

    /// One token- or line-level mutation.
    fn mutate_tokens(&mut self, input: &mut Vec<u8>) {
        let numbers = spans(input, is_number_byte, true);
        let words = spans(input, |b| !b.is_ascii_whitespace(), false);
        let lines = spans(input, |b| b != b'\n', false);
        let pick = |m: &mut Self, spans: &[(usize, usize)]| spans[m.below(spans.len())];
        match self.below(10) {
            0..=2 if !numbers.is_empty() => self.replace_number(input),
            3 if !words.is_empty() => {
                let (start, end) = pick(self, &words);
                input.drain(start..end);
            }
            4 if !words.is_empty() => {
                // Sometimes thousands of times: a file with an error in
                // every word must still be read in linear time and space.
                let (start, end) = pick(self, &words);
                let copies = if self.chance(0.25) {
                    1 + self.below(20_000)
                } else {
                    1
                };
                let mut word = input[start..end].to_vec();
                word.push(b' ');
                let copies = copies.min(MAX_INPUT / word.len() + 1);
                input.splice(start..start, word.repeat(copies));
            }
            5 if words.len() >= 2 => {
                let a = pick(self, &words);
                let b = pick(self, &words);
                swap(input, a, b);
            }
            6 if !lines.is_empty() => {
                let (start, end) = pick(self, &lines);
                input.drain(start..(end + 1).min(input.len()));
            }
            7 if !lines.is_empty() => {
                let (start, end) = pick(self, &lines);
                let copies = if self.chance(0.1) {
                    1 + self.below(200)
                } else {
                    1
                };
                let mut line = input[start..end].to_vec();
                line.push(b'\n');
                input.splice(start..start, line.repeat(copies));
            }
            8 if lines.len() >= 2 => {
                let a = pick(self, &lines);
                let b = pick(self, &lines);
                swap(input, a, b);
            }
            _ if !self.vocabulary.is_empty() => {
                let word = &self.vocabulary[self.below(self.vocabulary.len())];
                let at = if words.is_empty() {
                    0
                } else {
                    pick(self, &words).0
                };
                let separator = if self.chance(0.7) { b' ' } else { b'\n' };
                let mut insert = word.clone().into_bytes();
                insert.push(separator);
                input.splice(at..at, insert);
            }
            _ => self.mutate_bytes(input),
        }
    }

    /// Replaces a number of `input`, if it has one, by an extreme or a
    /// random one.
    fn replace_number(&mut self, input: &mut Vec<u8>) {
        let numbers = spans(input, is_number_byte, true);
        if numbers.is_empty() {
            return;
        }
        let (start, end) = numbers[self.below(numbers.len())];
        let number = if self.chance(0.8) {
            EXTREMES[self.below(EXTREMES.len())].to_string()
        } else {
            self.random_number()
        };
        input.splice(start..end, number.into_bytes());
    }

    /// A number of random sign, digits and exponent.
    fn random_number(&mut self) -> String {
        let sign = if self.chance(0.5) { "-" } else { "" };
        let mantissa = self.rng.uniform() * 10.0;
        let exponent = self.below(700) as i32 - 350;
        if self.chance(0.5) {
            format!("{sign}{}", self.rng.next_u32() >> self.below(32))
        } else {
            format!("{sign}{mantissa}e{exponent}")
        }
    }
}

/// Bytes that can be part of a number.
fn is_number_byte(b: u8) -> bool {
    b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+' | b'e' | b'E')
}

/// The maximal runs of bytes for which `inside` holds; with `digit`, only
/// runs holding a digit.
fn spans(input: &[u8], inside: impl Fn(u8) -> bool, digit: bool) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut start = None;
    for i in 0..=input.len() {
        match (start, input.get(i).is_some_and(|&b| inside(b))) {
            (None, true) => start = Some(i),
            (Some(s), false) => {
                if !digit || input[s..i].iter().any(u8::is_ascii_digit) {
                    spans.push((s, i));
                }
                start = None;
            }
            _ => {}
        }
    }
    spans
}

/// Swaps two ranges of `input`; overlapping ranges leave it unchanged.
fn swap(input: &mut Vec<u8>, a: (usize, usize), b: (usize, usize)) {
    let (first, second) = if a.0 <= b.0 { (a, b) } else { (b, a) };
    if first.1 > second.0 {
        return;
    }
    let mut out = Vec::with_capacity(input.len());
    out.extend_from_slice(&input[..first.0]);
    out.extend_from_slice(&input[second.0..second.1]);
    out.extend_from_slice(&input[first.1..second.0]);
    out.extend_from_slice(&input[first.0..first.1]);
    out.extend_from_slice(&input[second.1..]);
    *input = out;
}

#[test]
fn number_spans_hold_a_digit() {
    let spans = spans(b"s 1.5 -e x2 [0,-3e-4]", is_number_byte, true);
    assert_eq!(spans, [(2, 5), (10, 11), (13, 14), (15, 20)]);
}

#[test]
fn swapping_exchanges_two_ranges() {
    let mut text = b"ab cd ef".to_vec();
    swap(&mut text, (6, 8), (0, 2));
    assert_eq!(text, b"ef cd ab");
    swap(&mut text, (0, 4), (2, 5));
    assert_eq!(text, b"ef cd ab");
}
