//! Which FMI standard an FMU is packed for (`fxbody pack --fmi 2|3`). The library serves
//! both from one binary (its `fmi2*` and `fmi3*` exports); the version decides the model
//! description's schema, the `binaries/` folder names and the words of the documentation
//! page. It is not part of the resources, so an FMU's GUID (its FMI 3.0
//! instantiationToken) is the same whichever version it is packed for.

/// An FMI version this crate packs and serves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FmiVersion {
    /// FMI 2.0 (the default).
    #[default]
    Fmi2,
    /// FMI 3.0.
    Fmi3,
}

impl FmiVersion {
    /// The `fmiVersion` attribute: "2.0" or "3.0".
    pub fn number(self) -> &'static str {
        match self {
            FmiVersion::Fmi2 => "2.0",
            FmiVersion::Fmi3 => "3.0",
        }
    }

    /// The version named by `pack --fmi`: 2 or 3 (also "2.0", "3.0").
    pub fn parse(s: &str) -> Option<FmiVersion> {
        match s.trim() {
            "2" | "2.0" => Some(FmiVersion::Fmi2),
            "3" | "3.0" => Some(FmiVersion::Fmi3),
            _ => None,
        }
    }

    /// The `binaries/` folder of the packing build's own library: FMI 2.0's `linux64`,
    /// FMI 3.0's platform tuple `x86_64-linux`.
    pub fn native_platform(self) -> &'static str {
        match self {
            FmiVersion::Fmi2 => super::platforms::NATIVE,
            FmiVersion::Fmi3 => "x86_64-linux",
        }
    }

    /// The `binaries/` folders of a library added with `pack --binary PLATFORM=PATH`
    /// (`PLATFORM` an FMI 2.0 name, checked against `bytes` already): the name itself for
    /// FMI 2.0; for FMI 3.0 the platform tuple `<arch>-<sys>` of that platform (win64:
    /// x86_64-windows, linux32: x86-linux, ...), where a 64-bit Mach-O library goes to
    /// aarch64-darwin or x86_64-darwin by the CPU its header names, a universal one to
    /// both.
    pub fn platform_dirs(self, platform: &str, bytes: &[u8]) -> Vec<String> {
        if self == FmiVersion::Fmi2 {
            return vec![platform.to_string()];
        }
        let (bits64, sys) = (
            platform.ends_with("64"),
            platform.trim_end_matches(char::is_numeric),
        );
        let sys = match sys {
            "win" => "windows",
            other => other,
        };
        if !bits64 {
            return vec![format!("x86-{sys}")];
        }
        if sys == "darwin" {
            const ARM64: u32 = 0x0100_000c;
            let cpu = bytes
                .get(4..8)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
            if bytes.starts_with(&[0xca, 0xfe, 0xba, 0xbe]) {
                return vec!["aarch64-darwin".into(), "x86_64-darwin".into()];
            }
            if cpu == Some(ARM64) {
                return vec!["aarch64-darwin".into()];
            }
        }
        vec![format!("x86_64-{sys}")]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn platform_folders_follow_each_standard() {
        use FmiVersion::*;
        assert_eq!(Fmi2.platform_dirs("win64", b""), ["win64"]);
        for (fmi2, fmi3) in [
            ("win32", "x86-windows"),
            ("win64", "x86_64-windows"),
            ("linux32", "x86-linux"),
            ("linux64", "x86_64-linux"),
            ("darwin32", "x86-darwin"),
        ] {
            assert_eq!(Fmi3.platform_dirs(fmi2, b""), [fmi3]);
        }
        let mut arm = vec![0u8; 32];
        arm[..4].copy_from_slice(&0xfeed_facfu32.to_le_bytes());
        arm[4..8].copy_from_slice(&0x0100_000cu32.to_le_bytes());
        assert_eq!(Fmi3.platform_dirs("darwin64", &arm), ["aarch64-darwin"]);
        arm[4..8].copy_from_slice(&0x0100_0007u32.to_le_bytes());
        assert_eq!(Fmi3.platform_dirs("darwin64", &arm), ["x86_64-darwin"]);
        assert_eq!(
            Fmi3.platform_dirs("darwin64", &[0xca, 0xfe, 0xba, 0xbe]),
            ["aarch64-darwin", "x86_64-darwin"]
        );
        assert_eq!(Fmi3.native_platform(), "x86_64-linux");
        assert_eq!(FmiVersion::parse("3"), Some(Fmi3));
        assert_eq!(FmiVersion::parse("2.0"), Some(Fmi2));
        assert_eq!(FmiVersion::parse("4"), None);
    }
}
