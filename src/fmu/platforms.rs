//! The platforms an FMU carries: `binaries/linux64/` from the build that packs it, and
//! libraries built elsewhere added with `pack --binary PLATFORM=PATH`. Platform names are
//! FMI 2.0's (section 2.1.1 of the standard: win32, win64, linux32, linux64, darwin32,
//! darwin64), and a library is checked to be a shared library of that platform's kind
//! (ELF shared object, PE DLL, Mach-O dylib or bundle) with the right word size, from its
//! header, so that a wrong file is refused at packing rather than failing to load in a
//! master on another machine.

/// The platform names of FMI 2.0 with a binaries/ folder.
pub const FMI2_PLATFORMS: [&str; 6] = [
    "win32", "win64", "linux32", "linux64", "darwin32", "darwin64",
];

/// The platform the packing build's own library is stored under.
pub const NATIVE: &str = "linux64";

/// A platform name FMI 2.0 does not define.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown FMI 2.0 platform '{0}': expected one of win32, win64, linux32, linux64, darwin32, darwin64"
)]
pub struct UnknownPlatform(pub String);

/// Check a platform name against [`FMI2_PLATFORMS`].
pub fn check_platform(name: &str) -> Result<(), UnknownPlatform> {
    if FMI2_PLATFORMS.contains(&name) {
        Ok(())
    } else {
        Err(UnknownPlatform(name.to_string()))
    }
}

/// The library's file name inside `binaries/PLATFORM/` (FMI 2.0: the model identifier
/// with the platform's shared-library extension).
pub fn library_name(platform: &str, model_identifier: &str) -> String {
    let ext = if platform.starts_with("win") {
        "dll"
    } else if platform.starts_with("darwin") {
        "dylib"
    } else {
        "so"
    };
    format!("{model_identifier}.{ext}")
}

/// What a file's header says it is, in words for messages.
fn kind(bytes: &[u8]) -> String {
    let u16le = |o: usize| {
        bytes
            .get(o..o + 2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
    };
    let u32le = |o: usize| {
        bytes
            .get(o..o + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    if bytes.starts_with(b"\x7fELF") {
        let bits = match bytes.get(4) {
            Some(1) => "32-bit",
            Some(2) => "64-bit",
            _ => "?-bit",
        };
        let e_type = match bytes.get(5) {
            Some(2) => bytes.get(16..18).map(|b| u16::from_be_bytes([b[0], b[1]])),
            _ => u16le(16),
        };
        let what = if e_type == Some(3) {
            "shared library"
        } else {
            "executable or object (not a shared library)"
        };
        return format!("ELF {bits} {what}");
    }
    if bytes.starts_with(b"MZ") {
        let Some(pe) = u32le(0x3c).map(|o| o as usize) else {
            return "truncated DOS/PE file".into();
        };
        if bytes.get(pe..pe + 4) != Some(b"PE\0\0") {
            return "DOS executable (not a PE DLL)".into();
        }
        let bits = match u16le(pe + 4) {
            Some(0x14c) => "32-bit",
            Some(0x8664 | 0xaa64) => "64-bit",
            _ => "?-bit",
        };
        let dll = u16le(pe + 22).is_some_and(|c| c & 0x2000 != 0);
        let what = if dll { "DLL" } else { "executable (not a DLL)" };
        return format!("PE {bits} {what}");
    }
    let magic = u32le(0);
    if bytes.starts_with(&[0xca, 0xfe, 0xba, 0xbe]) {
        return "Mach-O universal library".into();
    }
    if matches!(magic, Some(0xfeed_face | 0xfeed_facf)) {
        let bits = if magic == Some(0xfeed_face) {
            "32-bit"
        } else {
            "64-bit"
        };
        let what = if matches!(u32le(12), Some(6 | 8)) {
            "dylib"
        } else {
            "executable or object (not a dylib)"
        };
        return format!("Mach-O {bits} {what}");
    }
    "not a shared library (no ELF, PE or Mach-O header)".into()
}

/// Check that `bytes` is a shared library for `platform`; the error says what the file
/// is instead.
pub fn check_library(platform: &str, bytes: &[u8]) -> Result<(), String> {
    check_platform(platform).map_err(|e| e.to_string())?;
    let bits = if platform.ends_with("64") {
        "64-bit"
    } else {
        "32-bit"
    };
    let expected = if platform.starts_with("win") {
        format!("PE {bits} DLL")
    } else if platform.starts_with("darwin") {
        format!("Mach-O {bits} dylib")
    } else {
        format!("ELF {bits} shared library")
    };
    let found = kind(bytes);
    if found == expected || (platform.starts_with("darwin") && found == "Mach-O universal library")
    {
        Ok(())
    } else {
        let article = if expected.starts_with('E') { "an" } else { "a" };
        Err(format!(
            "expected {article} {expected} for {platform}, found: {found}"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A minimal PE header: `machine`, DLL flag or not.
    pub(crate) fn pe(machine: u16, dll: bool) -> Vec<u8> {
        let mut b = vec![0u8; 0x100];
        b[..2].copy_from_slice(b"MZ");
        b[0x3c..0x40].copy_from_slice(&0x80u32.to_le_bytes());
        b[0x80..0x84].copy_from_slice(b"PE\0\0");
        b[0x84..0x86].copy_from_slice(&machine.to_le_bytes());
        let ch: u16 = if dll { 0x2022 } else { 0x0022 };
        b[0x96..0x98].copy_from_slice(&ch.to_le_bytes());
        b
    }

    #[test]
    fn headers_are_told_apart() {
        assert!(check_library("win64", &pe(0x8664, true)).is_ok());
        assert_eq!(
            check_library("win32", &pe(0x8664, true)).unwrap_err(),
            "expected a PE 32-bit DLL for win32, found: PE 64-bit DLL"
        );
        assert!(
            check_library("win64", &pe(0x8664, false))
                .unwrap_err()
                .contains("executable (not a DLL)")
        );
        let mut elf = vec![0u8; 64];
        elf[..4].copy_from_slice(b"\x7fELF");
        elf[4] = 2;
        elf[5] = 1;
        elf[16] = 3;
        assert!(check_library("linux64", &elf).is_ok());
        assert_eq!(
            check_library("win64", &elf).unwrap_err(),
            "expected a PE 64-bit DLL for win64, found: ELF 64-bit shared library"
        );
        let mut macho = vec![0u8; 32];
        macho[..4].copy_from_slice(&0xfeed_facfu32.to_le_bytes());
        macho[12] = 6;
        assert!(check_library("darwin64", &macho).is_ok());
        assert!(
            check_library("darwin64", b"#!/bin/sh\n")
                .unwrap_err()
                .contains("no ELF")
        );
        assert!(check_platform("win128").is_err());
        assert_eq!(library_name("darwin64", "m"), "m.dylib");
    }
}
