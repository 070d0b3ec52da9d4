//! Reading PDF functions (types 0, 2, 3 and 4) of shadings and tint transforms.

use lopdf::{Dictionary, Object};

use super::bits::BitReader;
use super::colour::Function;
use super::objects::{invalid, Objects};
use super::postscript::Program;
use crate::error::Error;

/// The deepest nesting of stitching functions.
const MAX_FUNCTION_DEPTH: usize = 8;
/// The most samples of a sampled function.
const MAX_SAMPLES: u64 = 1 << 20;
/// The most inputs of a sampled function (each evaluation interpolates between up to
/// `2^inputs` samples).
const MAX_SAMPLED_INPUTS: usize = 8;
/// The most bytes of a type 4 function's program.
const MAX_PROGRAM_BYTES: u64 = 1 << 20;

/// Reads a function of `inputs` inputs: of type 2 or 3 (one input by definition), of type 0
/// (up to [`MAX_SAMPLED_INPUTS`] inputs) or 4 (up to 32), or an array of them.
pub(crate) fn read_function(
    objects: Objects,
    object: &Object,
    what: &str,
    inputs: usize,
) -> Result<Function, Error> {
    read_function_at(objects, object, what, inputs, 0)
}

fn read_function_at(
    objects: Objects,
    object: &Object,
    what: &str,
    inputs: usize,
    depth: usize,
) -> Result<Function, Error> {
    if depth > MAX_FUNCTION_DEPTH {
        return Err(invalid(what, "functions nest too deep"));
    }
    let (resolved, _) = objects.resolve(object, what)?;
    if let Object::Array(items) = resolved {
        if items.is_empty() {
            return Err(invalid(what, "an empty array of functions"));
        }
        let functions = items
            .iter()
            .enumerate()
            .map(|(k, f)| read_function_at(objects, f, &format!("{what} [{k}]"), inputs, depth + 1))
            .collect::<Result<_, _>>()?;
        return Ok(Function::Array(functions));
    }
    let dict = objects.dict(resolved, what)?;
    let domain = read_numbers(objects, dict, b"Domain", what)?
        .ok_or_else(|| invalid(what, "the function has no Domain"))?;
    if domain.len() != 2 * inputs {
        return Err(invalid(
            what,
            format!(
                "the function must have {inputs} input{} (a Domain of {} numbers); it has {}",
                if inputs == 1 { "" } else { "s" },
                2 * inputs,
                domain.len()
            ),
        ));
    }
    let kind = objects
        .get(dict, b"FunctionType", what)?
        .ok_or_else(|| invalid(what, "the function has no FunctionType"))?;
    let kind = objects.number(kind, what)?;
    if kind == 4.0 {
        return read_postscript(objects, resolved, what, &domain);
    }
    if kind == 0.0 {
        return read_sampled(objects, resolved, what, &pairs(&domain));
    }
    if inputs != 1 && (kind == 2.0 || kind == 3.0) {
        return Err(invalid(
            what,
            format!(
                "a function of FunctionType {kind} has one input by definition (PDF 32000-1, \
                 7.10.3 and 7.10.4), but {inputs} inputs are needed here: {inputs} colourants \
                 need a function of type 0 or 4"
            ),
        ));
    }
    let domain = [domain[0], domain[1]];
    match kind {
        2.0 => read_exponential(objects, dict, what, domain),
        3.0 => read_stitching(objects, dict, what, domain, depth),
        other => Err(invalid(
            what,
            format!("FunctionType {other} is not read (0, 2, 3 and 4 are)"),
        )),
    }
}

/// The numbers of the entry `key` of `dict`, when it has one.
fn read_numbers(
    objects: Objects,
    dict: &Dictionary,
    key: &[u8],
    what: &str,
) -> Result<Option<Vec<f64>>, Error> {
    let label = format!("{what} /{}", String::from_utf8_lossy(key));
    objects
        .get(dict, key, what)?
        .map(|o| objects.numbers(o, &label))
        .transpose()
}

/// Reads an exponential function (type 2).
fn read_exponential(
    objects: Objects,
    dict: &Dictionary,
    what: &str,
    domain: [f64; 2],
) -> Result<Function, Error> {
    let c0 = read_numbers(objects, dict, b"C0", what)?.unwrap_or_else(|| vec![0.0]);
    let c1 = read_numbers(objects, dict, b"C1", what)?.unwrap_or_else(|| vec![1.0]);
    if c0.len() != c1.len() {
        return Err(invalid(what, "C0 and C1 differ in length"));
    }
    let n = objects
        .get(dict, b"N", what)?
        .ok_or_else(|| invalid(what, "the function has no N"))?;
    let n = objects.number(n, what)?;
    Ok(Function::Exponential { domain, c0, c1, n })
}

/// Reads a stitching function (type 3) of one input.
fn read_stitching(
    objects: Objects,
    dict: &Dictionary,
    what: &str,
    domain: [f64; 2],
    depth: usize,
) -> Result<Function, Error> {
    let list = objects
        .get(dict, b"Functions", what)?
        .ok_or_else(|| invalid(what, "the stitching function has no Functions"))?;
    let functions = match objects.resolve(list, what)?.0 {
        Object::Array(items) if !items.is_empty() => items
            .iter()
            .enumerate()
            .map(|(k, f)| {
                let label = format!("{what} /Functions [{k}]");
                read_function_at(objects, f, &label, 1, depth + 1)
            })
            .collect::<Result<Vec<_>, _>>()?,
        _ => return Err(invalid(what, "Functions must be a non-empty array")),
    };
    let bounds = read_numbers(objects, dict, b"Bounds", what)?.unwrap_or_default();
    let encode = read_numbers(objects, dict, b"Encode", what)?.unwrap_or_default();
    if bounds.len() + 1 != functions.len() || encode.len() != 2 * functions.len() {
        return Err(invalid(
            what,
            format!(
                "{} functions need {} Bounds and {} Encode numbers; found {} and {}",
                functions.len(),
                functions.len() - 1,
                2 * functions.len(),
                bounds.len(),
                encode.len()
            ),
        ));
    }
    let encode = encode.chunks(2).map(|p| [p[0], p[1]]).collect();
    Ok(Function::Stitching {
        domain,
        functions,
        bounds,
        encode,
    })
}

/// Reads a PostScript calculator function (type 4) whose `Domain` is `domain`, and runs it
/// at the corners and the centre of its domain, so that a program that fails there is an
/// error naming the object rather than a colour.
fn read_postscript(
    objects: Objects,
    object: &Object,
    what: &str,
    domain: &[f64],
) -> Result<Function, Error> {
    let stream = objects.stream(object, what)?;
    let range = read_numbers(objects, &stream.dict, b"Range", what)?
        .ok_or_else(|| invalid(what, "the type 4 function has no Range"))?;
    if range.is_empty() || range.len() % 2 != 0 || domain.len() > 64 {
        return Err(invalid(
            what,
            "Range must be pairs of numbers, and the inputs at most 32",
        ));
    }
    let source = objects.stream_data(stream, what, MAX_PROGRAM_BYTES)?;
    let program = Program::parse(&source)
        .map_err(|e| invalid(what, format!("its PostScript program cannot be read: {e}")))?;
    let function = Function::PostScript {
        domain: pairs(domain),
        range: pairs(&range),
        program,
    };
    for inputs in trial_inputs(&pairs(domain)) {
        if let Err(e) = function.try_eval(&inputs) {
            return Err(invalid(
                what,
                format!("its PostScript program fails at the inputs {inputs:?}: {e}"),
            ));
        }
    }
    Ok(function)
}

/// The numbers `v` in pairs.
fn pairs(v: &[f64]) -> Vec<[f64; 2]> {
    v.chunks_exact(2).map(|p| [p[0], p[1]]).collect()
}

/// The inputs a type 4 function is tried at when read: the centre of its domain and its
/// corners (the first 64 of them).
fn trial_inputs(domain: &[[f64; 2]]) -> Vec<Vec<f64>> {
    let centre: Vec<f64> = domain.iter().map(|d| (d[0] + d[1]) / 2.0).collect();
    let corners = (0u64..(1u64 << domain.len().min(6))).map(|bits| {
        domain
            .iter()
            .enumerate()
            .map(|(k, d)| if (bits >> k) & 1 == 1 { d[1] } else { d[0] })
            .collect()
    });
    std::iter::once(centre).chain(corners).collect()
}

/// Reads a sampled function (type 0) over `domain` (a range per input).
fn read_sampled(
    objects: Objects,
    object: &Object,
    what: &str,
    domain: &[[f64; 2]],
) -> Result<Function, Error> {
    let stream = objects.stream(object, what)?;
    let dict = &stream.dict;
    let numbers = |key: &[u8]| read_numbers(objects, dict, key, what);
    let inputs = domain.len();
    let size = numbers(b"Size")?.ok_or_else(|| invalid(what, "the function has no Size"))?;
    let size = sample_counts(&size, inputs, what)?;
    let range = numbers(b"Range")?.ok_or_else(|| invalid(what, "the function has no Range"))?;
    let bits = objects
        .get(dict, b"BitsPerSample", what)?
        .ok_or_else(|| invalid(what, "the function has no BitsPerSample"))?;
    let bits = objects.number(bits, &format!("{what} /BitsPerSample"))?;
    if ![1.0, 2.0, 4.0, 8.0, 12.0, 16.0, 24.0, 32.0].contains(&bits) {
        return Err(invalid(
            what,
            format!("BitsPerSample {bits} is not 1, 2, 4, 8, 12, 16, 24 or 32"),
        ));
    }
    if range.len() < 2 || range.len() % 2 != 0 {
        return Err(invalid(what, "Range must be pairs of numbers"));
    }
    let default_encode: Vec<f64> = size.iter().flat_map(|&s| [0.0, (s - 1) as f64]).collect();
    let encode = numbers(b"Encode")?.unwrap_or(default_encode);
    let decode = numbers(b"Decode")?.unwrap_or_else(|| range.clone());
    if encode.len() != 2 * inputs || decode.len() != range.len() {
        return Err(invalid(
            what,
            format!(
                "Encode must have {} numbers (2 an input) and Decode {} (2 an output)",
                2 * inputs,
                range.len()
            ),
        ));
    }
    let data = objects.stream_data(stream, what, MAX_SAMPLES * 8)?;
    let samples = decode_samples(
        &data,
        size.iter().product(),
        bits as u32,
        &range,
        &decode,
        what,
    )?;
    Ok(Function::Sampled {
        domain: domain.to_vec(),
        encode: pairs(&encode),
        size,
        samples,
        outputs: range.len() / 2,
    })
}

/// The `Size` of a sampled function of `inputs` inputs: a count from 1 up an input, at most
/// [`MAX_SAMPLES`] in all.
fn sample_counts(size: &[f64], inputs: usize, what: &str) -> Result<Vec<usize>, Error> {
    if inputs > MAX_SAMPLED_INPUTS {
        return Err(invalid(
            what,
            format!(
                "a sampled function of {inputs} inputs is not read (at most {MAX_SAMPLED_INPUTS})"
            ),
        ));
    }
    let counts_ok = size.len() == inputs
        && size.iter().all(|s| s.fract() == 0.0 && *s >= 1.0)
        && size
            .iter()
            .try_fold(1.0f64, |all, s| {
                let all = all * s;
                (all <= MAX_SAMPLES as f64).then_some(all)
            })
            .is_some();
    if !counts_ok {
        return Err(invalid(
            what,
            format!(
                "Size must be {inputs} whole count{} of at least 1, of at most {MAX_SAMPLES} samples in all",
                if inputs == 1 { "" } else { "s" }
            ),
        ));
    }
    Ok(size.iter().map(|&s| s as usize).collect())
}

/// The `count` samples of `data`, `range.len() / 2` outputs each of `bits` bits, decoded by
/// `decode` and clipped to `range`.
fn decode_samples(
    data: &[u8],
    count: usize,
    bits: u32,
    range: &[f64],
    decode: &[f64],
    what: &str,
) -> Result<Vec<f64>, Error> {
    let outputs = range.len() / 2;
    let needed = (count as u64) * (outputs as u64) * u64::from(bits);
    if (data.len() as u64) * 8 < needed {
        return Err(invalid(
            what,
            format!(
                "the stream holds {} bytes, fewer than its {count} samples need",
                data.len()
            ),
        ));
    }
    let mut reader = BitReader::new(data);
    let max = ((1u64 << bits) - 1) as f64;
    let mut samples = Vec::with_capacity(count * outputs);
    for _ in 0..count {
        for k in 0..outputs {
            let raw = reader.read(bits).unwrap_or(0) as f64;
            let value = decode[2 * k] + raw * (decode[2 * k + 1] - decode[2 * k]) / max;
            samples.push(value.clamp(
                range[2 * k].min(range[2 * k + 1]),
                range[2 * k].max(range[2 * k + 1]),
            ));
        }
    }
    Ok(samples)
}
