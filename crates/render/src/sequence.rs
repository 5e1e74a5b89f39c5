//! Frame ranges and numbered image sequences (`frame-0000.png`, …).

use std::fmt;
use std::str::FromStr;

/// A half-open range of animation frames `start..end`, written `"A..B"` in scene files and
/// on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameRange {
    /// First frame.
    pub start: usize,
    /// One past the last frame.
    pub end: usize,
}

impl FrameRange {
    /// Number of frames.
    pub fn len(&self) -> usize {
        self.end.saturating_sub(self.start)
    }

    /// True when the range holds no frame.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The frames, in order.
    pub fn iter(&self) -> std::ops::Range<usize> {
        self.start..self.end
    }

    /// Checks the range against an animation of `count` frames.
    ///
    /// # Errors
    /// A message naming the range and the count when it is empty or ends past the animation.
    pub fn check(&self, count: usize) -> Result<(), String> {
        if self.is_empty() {
            return Err(format!("frames {self} is empty; write A..B with A < B"));
        }
        if self.end > count {
            return Err(format!(
                "frames {self} ends past the animation's {count} frames (0..{count})"
            ));
        }
        Ok(())
    }
}

impl fmt::Display for FrameRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}..{}", self.start, self.end)
    }
}

impl FromStr for FrameRange {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || format!("frame range {s:?} is not of the form A..B (e.g. 0..120)");
        let (a, b) = s.trim().split_once("..").ok_or_else(bad)?;
        let start: usize = a.trim().parse().map_err(|_| bad())?;
        let end: usize = b.trim().parse().map_err(|_| bad())?;
        if end <= start {
            return Err(format!(
                "frame range {s:?} is empty; the end must exceed the start"
            ));
        }
        Ok(Self { start, end })
    }
}

/// The file name of frame `index` in a sequence: `{stem}-{index:04}.{ext}`.
pub fn frame_file_name(stem: &str, index: usize, ext: &str) -> String {
    format!("{stem}-{index:04}.{ext}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse_check_and_name_frames() {
        let r: FrameRange = "0..120".parse().unwrap();
        assert_eq!((r.start, r.end, r.len()), (0, 120, 120));
        assert_eq!(r.to_string(), "0..120");
        assert!(r.check(120).is_ok());
        assert!(r.check(119).unwrap_err().contains("119"));
        for bad in ["", "5", "3..3", "4..2", "a..b", "-1..4", "0...3"] {
            assert!(bad.parse::<FrameRange>().is_err(), "{bad:?}");
        }
        assert_eq!(frame_file_name("frame", 7, "png"), "frame-0007.png");
        assert_eq!(frame_file_name("frame", 12345, "exr"), "frame-12345.exr");
    }
}
