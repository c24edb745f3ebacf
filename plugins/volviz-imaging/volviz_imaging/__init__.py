"""volviz reader plugin: the volume formats of medical and neuro imaging, read by the field's own libraries.

Registered through the ``volviz.readers`` entry point (``volviz_imaging.specs:SPECS``); ``volviz.io.read`` dispatches to
the loaders here, each run in volviz's isolated reader process (``volviz.io.isolated``):

- NIfTI-1 / NIfTI-2 (.nii, .nii.gz, .hdr + .img), Analyze 7.5 and FreeSurfer MGH (.mgh, .mgz): nibabel
  (``volviz_imaging.nifti``); 4D files are time series.
- MINC 1 and 2 (.mnc; BrainWeb, the MNI templates): nibabel (``volviz_imaging.minc``); a time dimension is a time
  series.
- NRRD (.nrrd, .nhdr + data file; raw, text, gzip, bzip2): pynrrd (``volviz_imaging.nrrd_files``).
- DICOM series (a folder, or any slice of the series, or a multi-frame file): pydicom (``volviz_imaging.dicom``).
- MRC / CCP4 density maps (.mrc, .map, .ccp4, .rec): mrcfile (``volviz_imaging.mrc``), in Angstrom.
- Gaussian cube files (.cube): electron densities, orbitals and potentials, in Angstrom (``volviz_imaging.cube``).
- OME-Zarr images and Zarr arrays (folders): zarr-python (``volviz_imaging.omezarr``), codecs checked first.

Every medical volume is placed in RAS millimetres on the world axes nearest to its own
(``volviz_imaging.placement``), so a head from any of these formats lands where the others put it.
"""
from volviz_imaging.specs import SPECS

__all__ = ["SPECS"]
