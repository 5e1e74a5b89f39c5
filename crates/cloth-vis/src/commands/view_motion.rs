//! Motion for `cloth-vis view` from outside a scene's own clip: a jump map played endlessly
//! (thesis §3.2) with motion control — `C` sends the player to the next cell at the best
//! transition ahead (§3.2.2) — and a compressed animation (`.cpca`, §3.3) streamed through the
//! GPU decoder one frame at a time. Either way each frame is a new pose of the scene's object:
//! M and the lighting follow it.

use anim_pca::compress::GpuDecoder;
use anim_pca::{Clip, GeneratedFrame, JumpMap, JumpMapParams, PlaybackParams, Player};
use glam::Vec3;

/// A source of poses for object 0 of the viewed scene.
pub enum Motion {
    /// A jump map's player.
    JumpMap(Box<JumpMotion>),
    /// A `.cpca` on the GPU.
    Cpca(CpcaMotion),
}

impl Motion {
    /// The next pose (object space).
    pub fn next(&mut self) -> anyhow::Result<Vec<Vec3>> {
        match self {
            Motion::JumpMap(j) => j.next(),
            Motion::Cpca(c) => c.step(1),
        }
    }

    /// One line for the overlay.
    pub fn status(&self) -> String {
        match self {
            Motion::JumpMap(j) => j.status(),
            Motion::Cpca(c) => format!(
                "cpca frame {} of {} (GPU decoder)",
                c.frame,
                c.decoder.frames()
            ),
        }
    }
}

/// A jump map played endlessly. The map and the clips live as long as the process (the
/// player borrows them; a viewer builds one and runs until it closes).
pub struct JumpMotion {
    map: &'static JumpMap,
    clips: Vec<&'static [Vec3]>,
    player: Player<'static>,
    /// The last frame played.
    previous: Option<GeneratedFrame>,
    offset: Vec3,
    cells: usize,
}

impl JumpMotion {
    /// Analyse `cells` (the first is the viewed clip; each one clip of frames, all with the
    /// same vertex count) and start playing.
    ///
    /// # Errors
    /// The analysis's and the player's errors (too few frames, differing vertex counts).
    pub fn new(cells: Vec<Vec<Vec<Vec3>>>, seed: u64) -> anyhow::Result<Self> {
        let cells: &'static [Vec<Vec<Vec3>>] = Box::leak(cells.into_boxed_slice());
        let clips: Vec<Clip<'_>> = cells.iter().map(|c| Clip::new(c)).collect();
        let map: &'static JumpMap = Box::leak(Box::new(JumpMap::analyze_cells(
            &clips,
            &JumpMapParams::default(),
        )?));
        let playback = PlaybackParams {
            seed,
            ..PlaybackParams::default()
        };
        let player = Player::new(map, &playback)?;
        Ok(Self {
            map,
            clips: cells.iter().flatten().map(Vec::as_slice).collect(),
            player,
            previous: None,
            offset: Vec3::ZERO,
            cells: cells.len(),
        })
    }

    /// The next generated frame: the clip's own frame, or a cross-fade inside a blend, moved
    /// along by the root motion the map extracted.
    fn next(&mut self) -> anyhow::Result<Vec<Vec3>> {
        let frame = self.player.next_frame();
        self.offset = match self.previous {
            None => self.map.root_offsets(&[frame])[0],
            Some(previous) => {
                let o = self.map.root_offsets(&[previous, frame]);
                self.offset + (o[1] - o[0])
            }
        };
        self.previous = Some(frame);
        let mut out = vec![Vec3::ZERO; self.map.n_vertices()];
        self.map
            .exact_frame_into(&self.clips, &frame, self.offset, &mut out)?;
        Ok(out)
    }

    /// Motion control: head for the next cell (cyclically) at the best transition ahead.
    pub fn next_cell(&mut self) -> anyhow::Result<usize> {
        let cell = (self.player.current_cell() + 1) % self.cells;
        self.player.set_target_cell(cell)?;
        Ok(cell)
    }

    fn status(&self) -> String {
        let target = self
            .player
            .target_cell()
            .map(|t| format!(" → cell {t}"))
            .unwrap_or_default();
        let shown = match self.previous {
            None => "no frame yet".to_owned(),
            Some(f) if f.is_key() => format!("clip frame {}", f.from),
            Some(f) => format!("blend {}→{} α {:.2}", f.from, f.to, f.alpha),
        };
        format!(
            "jump map: {shown}, cell {} of {}{target} (C: next cell)",
            self.player.current_cell(),
            self.cells
        )
    }
}

/// A compressed animation resident on the GPU, decoded frame by frame.
pub struct CpcaMotion {
    decoder: GpuDecoder,
    frame: usize,
}

impl CpcaMotion {
    /// Upload `data` to the GPU decoder, starting at `frame`.
    ///
    /// # Errors
    /// The decoder's errors (buffers beyond the device's limits).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        data: &anim_pca::Compressed,
        frame: usize,
    ) -> anyhow::Result<Self> {
        Ok(Self {
            decoder: GpuDecoder::new(device, queue, data)?,
            frame,
        })
    }

    /// Decode `frame` (modulo the frame count) on the GPU and read it back.
    pub fn seek(&mut self, frame: usize) -> anyhow::Result<Vec<Vec3>> {
        self.frame = frame % self.decoder.frames().max(1);
        Ok(self.decoder.read_frame(self.frame)?)
    }

    /// Decode the frame `by` frames on (looping) on the GPU and read it back.
    pub fn step(&mut self, by: isize) -> anyhow::Result<Vec<Vec3>> {
        let n = self.decoder.frames().max(1) as isize;
        self.frame = (self.frame as isize + by).rem_euclid(n) as usize;
        Ok(self.decoder.read_frame(self.frame)?)
    }
}
