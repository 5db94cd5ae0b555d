//! Errors of the `.fxb` reader. Every variant that comes from the text names the file,
//! the line, the block (number and name) and what was expected against what was found,
//! so that a user can go straight to the offending line.

use std::fmt;

/// A block of the file (FORMULATION.md section 1), with the sub-block for blocks 12, 13.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Block {
    /// Block number, 1 to 13.
    pub number: u8,
    /// Sub-block `m = 3(k-1)+l`, 1 to 9, for blocks 12 and 13.
    pub sub: Option<u8>,
}

impl Block {
    /// A whole block.
    pub const fn new(number: u8) -> Block {
        Block { number, sub: None }
    }

    /// Sub-block `m` (1-based) of block 12 or 13.
    pub const fn sub(number: u8, m: u8) -> Block {
        Block {
            number,
            sub: Some(m),
        }
    }

    /// The block's name as the reference guide describes it.
    pub fn name(&self) -> &'static str {
        match self.number {
            1 => "general data Nbmod Nbstat Nbnod Irot Idamp Iblo Ifile",
            2 => "node IDs",
            3 => "initial frame P0 and Freq",
            4 => "Rayleigh damping",
            5 => "rigid modes 1-12",
            6 => "rotational rigid modes 13-15",
            7 => "local modes",
            8 => "local mass m_L",
            9 => "local stiffness K_L, full part",
            10 => "local stiffness K_L, diagonal part",
            11 => "rigid mass M_R",
            12 => "coupled mass M_C",
            13 => "coupled stiffness K_C",
            _ => "unknown block",
        }
    }
}

impl fmt::Display for Block {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "block {} ({})", self.number, self.name())?;
        if let Some(m) = self.sub {
            let k = (m.saturating_sub(1)) / 3 + 1;
            let l = (m.saturating_sub(1)) % 3 + 1;
            let sym = if self.number == 12 { "M_C" } else { "K_C" };
            write!(f, ", sub-block {m} ({sym},{k}{l})")?;
        }
        Ok(())
    }
}

/// Where in the text an error was found: file, 1-based line, block.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct At {
    /// File name as given by the caller.
    pub file: String,
    /// 1-based line number.
    pub line: usize,
    /// The block being read.
    pub block: Block,
}

impl fmt::Display for At {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}: {}", self.file, self.line, self.block)
    }
}

/// Everything that can go wrong reading a `.fxb` file.
#[derive(Debug, thiserror::Error)]
pub enum FxbError {
    /// The file could not be read at all.
    #[error("{file}: cannot read the body file: {}", super::input::describe(.source))]
    Io {
        /// File name.
        file: String,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// The text ended inside a block.
    #[error("{at}: unexpected end of file: expected {expected}, found end of file")]
    UnexpectedEof {
        /// Last line of the file and the block being read.
        at: At,
        /// What was still missing.
        expected: String,
    },
    /// A field or value that is not a number of the expected kind.
    #[error("{at}: cannot read {expected}: {found}")]
    Unparsable {
        /// Where.
        at: At,
        /// The kind of value expected.
        expected: String,
        /// What the fixed-column and the blank-separated readings found.
        found: String,
    },
    /// A line with fewer values than the block needs there.
    #[error(
        "{at}: short line: expected {expected} values on this line ({what}), found {found} \
         (only the last line of a block or sub-block may be short)"
    )]
    ShortLine {
        /// Where.
        at: At,
        /// Values this line must hold.
        expected: usize,
        /// Values it holds.
        found: usize,
        /// Which values were due.
        what: String,
    },
    /// A line with more values than the block has room for there.
    #[error(
        "{at}: too many values on the line: expected at most {expected} ({what}), found {found} \
         (each block, sub-block and mode line starts on a new line)"
    )]
    TooManyValues {
        /// Where.
        at: At,
        /// Values this line may hold.
        expected: usize,
        /// Values it holds.
        found: usize,
        /// Which values were due.
        what: String,
    },
    /// A negative Nbmod, Nbstat or Nbnod.
    #[error("{at}: {name} must be a count >= 0, found {found}")]
    NegativeCount {
        /// Where.
        at: At,
        /// Which count.
        name: &'static str,
        /// The value in the file.
        found: i64,
    },
    /// A flag that is neither 0 nor 1.
    #[error("{at}: flag {name} must be 0 or 1, found {found}")]
    BadFlag {
        /// Where.
        at: At,
        /// Which flag.
        name: &'static str,
        /// The value in the file.
        found: i64,
    },
    /// More static modes than modes.
    #[error(
        "{at}: Nbstat must not exceed Nbmod: expected Nbstat <= {nbmod}, found Nbstat = {nbstat}"
    )]
    NbstatExceedsNbmod {
        /// Where.
        at: At,
        /// Nbstat in the file.
        nbstat: usize,
        /// Nbmod in the file.
        nbmod: usize,
    },
    /// A node ID listed twice in block 2.
    #[error(
        "{at}: duplicate node ID {id}: expected each node once, found it already on line {first_line}"
    )]
    DuplicateNodeId {
        /// Where the second occurrence is.
        at: At,
        /// The node ID.
        id: i64,
        /// Line of the first occurrence.
        first_line: usize,
    },
    /// A node ID that is not a positive integer.
    #[error("{at}: node ID must be > 0, found {id}")]
    BadNodeId {
        /// Where.
        at: At,
        /// The value in the file.
        id: i64,
    },
    /// Data lines after the last block the header calls for.
    #[error("{at}: data after the last block: expected end of file, found '{found}'")]
    TrailingData {
        /// The extra line; `block` is the last block read.
        at: At,
        /// The line's text (shortened).
        found: String,
    },
    /// A line that the fixed-column and blank-separated readings read differently.
    #[error(
        "{at}: ambiguous line: the fixed-column reading (as Radioss reads it) gives {fixed} \
         but the blank-separated reading gives {free}; align the values in {width}-column \
         fields or separate them so that both readings agree{note}"
    )]
    Ambiguous {
        /// Where.
        at: At,
        /// Values of the fixed-column reading.
        fixed: String,
        /// Values of the blank-separated reading.
        free: String,
        /// Field width of the block (8 for integers, 16 for reals).
        width: usize,
        /// Extra hint (text past column 100, tabs).
        note: String,
    },
    /// Header counts that the rest of the file cannot possibly hold.
    #[error(
        "{at}: the header claims {claim}: that needs at least {needed} more values, but only \
         {available} bytes remain in the file"
    )]
    TooLarge {
        /// The header line.
        at: At,
        /// The header values.
        claim: String,
        /// Values the header asks for (saturated at u64::MAX when it overflows).
        needed: u128,
        /// Bytes left after the header.
        available: usize,
    },
}
