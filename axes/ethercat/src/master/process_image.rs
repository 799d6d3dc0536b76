//! Where each axis' PDOs sit in the logical process image, read back from the stations' FMMUs
//! after OP: each axis has its part of its station's images, the slots' PDOs in assignment order.

use std::ops::Range;

use ethercrab::MainDevice;

use super::error::{step, EthercatError};
use super::group::OpGroup;
use super::pump::Wire;
use super::segment::{SegmentConfig, SegmentStation};
use crate::register as reg;

/// One axis' place in the process image and its images.
#[derive(Debug)]
pub(super) struct AxisImage {
    /// The SubDevice (position in the line) and the axis' slot on it.
    pub(super) station: usize,
    pub(super) slot: u8,
    pub(super) outputs: Range<usize>,
    pub(super) inputs: Range<usize>,
    pub(super) rx: Vec<u8>,
    pub(super) tx: Vec<u8>,
}

/// The process image the segment runs in OP.
pub(super) struct ProcessImage {
    /// The axes' places and images, in axis order.
    pub(super) axes: Vec<AxisImage>,
    /// Bytes of the logical process image.
    pub(super) pdi_len: usize,
    /// The LRW's working counter when every station takes part (3 each: read and write).
    pub(super) expected_wkc: u16,
}

impl ProcessImage {
    /// Reads back every station's FMMUs and lays its axes' images out in them, checking that
    /// the image a station runs is the one its maps need.
    pub(super) fn read_back(
        group: &OpGroup,
        maindevice: &MainDevice<'static>,
        wire: &mut Wire<'_>,
        config: &SegmentConfig,
        plans: &[SegmentStation],
    ) -> Result<Self, EthercatError> {
        let mut axes: Vec<Option<AxisImage>> = config.drives.iter().map(|_| None).collect();
        let mut pdi_len = 0usize;
        let mut expected_wkc = 0u16;
        for (position, plan) in plans.iter().enumerate() {
            let sd = step("SubDevice lookup", group.subdevice(maindevice, position))?;
            let (outputs, inputs) = read_fmmus(&sd, wire)?;
            let lens: Vec<(usize, usize)> = (0..plan.slots.len())
                .map(|slot| {
                    let p = plan.slot_profile(config, slot);
                    (p.pdo.rx.byte_len(), p.pdo.tx.byte_len())
                })
                .collect();
            let rx_len: usize = lens.iter().map(|l| l.0).sum();
            let tx_len: usize = lens.iter().map(|l| l.1).sum();
            if outputs.len() != rx_len || inputs.len() != tx_len {
                let d = &config.drives[plan.first_axis()];
                return Err(EthercatError::ProcessImage {
                position,
                axis: d.axis.clone(),
                what: format!(
                    "process image of {} output and {} input bytes, the {} maps need {rx_len} and {tx_len}",
                    outputs.len(),
                    inputs.len(),
                    d.profile.model.as_str()
                ),
            });
            }
            pdi_len = pdi_len.max(outputs.end).max(inputs.end);
            expected_wkc += 3;
            let (mut o, mut i) = (outputs.start, inputs.start);
            for (slot, (&(rl, tl), a)) in lens.iter().zip(&plan.slots).enumerate() {
                if let Some(a) = *a {
                    axes[a] = Some(AxisImage {
                        station: position,
                        slot: slot as u8,
                        outputs: o..o + rl,
                        inputs: i..i + tl,
                        rx: vec![0; rl],
                        tx: vec![0; tl],
                    });
                }
                o += rl;
                i += tl;
            }
        }
        Ok(ProcessImage {
            axes: axes.into_iter().flatten().collect(),
            pdi_len,
            expected_wkc,
        })
    }
}

/// The output and input ranges a station's enabled FMMUs map in the logical image.
fn read_fmmus<S: std::ops::Deref<Target = ethercrab::SubDevice>>(
    sd: &ethercrab::SubDeviceRef<'_, S>,
    wire: &mut Wire<'_>,
) -> Result<(Range<usize>, Range<usize>), EthercatError> {
    let mut outputs = 0..0;
    let mut inputs = 0..0;
    for n in 0..4u8 {
        let r = reg::fmmu(n);
        let read = async {
            let start: u32 = sd.register_read(r).await?;
            let len: u16 = sd.register_read(r + 4).await?;
            let kind: u8 = sd.register_read(r + 11).await?;
            let enable: u8 = sd.register_read(r + 12).await?;
            Ok::<_, ethercrab::error::Error>((start as usize, usize::from(len), kind, enable))
        };
        let (start, len, kind, enable) = wire.run("FMMU read-back", read)?;
        if enable & 1 == 0 {
            continue;
        }
        match kind & 3 {
            2 => outputs = start..start + len,
            1 => inputs = start..start + len,
            _ => {}
        }
    }
    Ok((outputs, inputs))
}
