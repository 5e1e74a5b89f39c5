//! Prefilter a lat-long HDR map with a spherical Gaussian and write it as EXR.
//!
//! ```text
//! cargo run --release -p lightsphere --example prefilter -- IN.hdr SIGMA_DEG OUT.exr
//! ```

use lightsphere::Environment;
use std::path::PathBuf;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    atomic_out::remove_temporaries_on_signal()?;
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [input, sigma, output] = args.as_slice() else {
        return Err("usage: prefilter IN.hdr|IN.exr SIGMA_DEG OUT.exr".into());
    };
    let sigma: f64 = sigma.parse()?;
    let env = Environment::load(&PathBuf::from(input))?;
    let start = Instant::now();
    let filtered = env.prefiltered(sigma)?;
    let seconds = start.elapsed().as_secs_f64();
    filtered.write_exr(&PathBuf::from(output))?;
    let (p, q) = (env.total_power(), filtered.total_power());
    println!(
        "{}×{} → {}×{} at σ = {sigma}° in {:.0} ms; power {:.6e} → {:.6e} (relative change {:+.2e})",
        env.width(),
        env.height(),
        filtered.width(),
        filtered.height(),
        seconds * 1e3,
        p[1],
        q[1],
        q[1] / p[1] - 1.0
    );
    Ok(())
}
