#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
# Writes one small oblique volume as NIfTI (nibabel), a DICOM series (pydicom) and NRRD (written
# by hand here; Debian 12 has no python3-nrrd), plus truth.txt, for the C++ cross-format test.
# Exit code 77: a needed module is missing (the test skips).
import gzip
import os
import sys

try:
    import nibabel
    import numpy as np
    import pydicom
    from pydicom.dataset import FileDataset, FileMetaDataset
    from pydicom.uid import ExplicitVRLittleEndian, generate_uid
    from pydicom.valuerep import format_number_as_ds
except ImportError as error:
    print(f"volume_oracle.py: {error}", file=sys.stderr)
    sys.exit(77)

NX, NY, NZ = 7, 6, 5
SPACING_MM = np.array([0.8, 0.65, 1.7])
ORIGIN_LPS = np.array([-31.5, 17.25, -42.0])  # centre of voxel (0, 0, 0)
CT_IMAGE_STORAGE = "1.2.840.10008.5.1.4.1.1.2"
SERIES_UID = "1.2.826.0.1.3680043.2.1125.7.1"


def rotation(axis, angle_rad):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle_rad) * k + (1 - np.cos(angle_rad)) * k @ k


ROTATION = rotation([1.0, 2.0, 3.0], 0.5)
LPS_FROM_IJK = np.eye(4)
LPS_FROM_IJK[:3, :3] = ROTATION * SPACING_MM  # columns: direction * spacing
LPS_FROM_IJK[:3, 3] = ORIGIN_LPS
RAS_FROM_LPS = np.diag([-1.0, -1.0, 1.0, 1.0])

i, j, k = np.meshgrid(np.arange(NX), np.arange(NY), np.arange(NZ), indexing="ij")
VALUES = (3 * (i + 7 * j + 42 * k) - 600).astype(np.int16)  # [i, j, k], all distinct


def write_truth(folder):
    with open(os.path.join(folder, "truth.txt"), "w") as out:
        out.write(f"{NX} {NY} {NZ}\n")
        out.write(" ".join(repr(float(x)) for x in LPS_FROM_IJK.ravel()) + "\n")
        out.write(" ".join(str(int(v)) for v in VALUES.ravel(order="F")) + "\n")


def write_nifti(folder):
    ras = RAS_FROM_LPS @ LPS_FROM_IJK
    both = nibabel.Nifti1Image(VALUES, ras)
    both.set_sform(ras, code=1)
    both.set_qform(ras, code=1)
    nibabel.save(both, os.path.join(folder, "oblique.nii.gz"))
    qform_only = nibabel.Nifti1Image(VALUES, ras)
    qform_only.set_sform(ras, code=0)
    qform_only.set_qform(ras, code=1)
    nibabel.save(qform_only, os.path.join(folder, "oblique_qform.nii"))


def write_dicom(folder):
    os.makedirs(folder, exist_ok=True)
    study_uid = generate_uid()
    for slice_k in range(NZ):
        slope, intercept = (1.0, 0.0) if slice_k % 2 == 0 else (3.0, -600.0)
        stored = ((VALUES[:, :, slice_k].astype(float) - intercept) / slope).astype("<i2")
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = CT_IMAGE_STORAGE
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        name = os.path.join(folder, f"IM{(3 * slice_k + 2) % NZ:04d}.dcm")  # shuffled order
        ds = FileDataset(name, {}, file_meta=meta, preamble=b"\0" * 128)
        ds.is_little_endian, ds.is_implicit_VR = True, False
        ds.SOPClassUID, ds.SOPInstanceUID = CT_IMAGE_STORAGE, meta.MediaStorageSOPInstanceUID
        ds.Modality, ds.StudyInstanceUID, ds.SeriesInstanceUID = "CT", study_uid, SERIES_UID
        ds.SeriesDescription = "oblique oracle"
        position = ORIGIN_LPS + slice_k * SPACING_MM[2] * ROTATION[:, 2]
        ds.ImagePositionPatient = [format_number_as_ds(float(x)) for x in position]
        ds.ImageOrientationPatient = [
            format_number_as_ds(float(x)) for x in np.concatenate([ROTATION[:, 0], ROTATION[:, 1]])]
        ds.PixelSpacing = [format_number_as_ds(float(SPACING_MM[1])),  # between rows
                           format_number_as_ds(float(SPACING_MM[0]))]  # between columns
        ds.Rows, ds.Columns = NY, NX
        ds.SamplesPerPixel, ds.PhotometricInterpretation = 1, "MONOCHROME2"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 1
        ds.RescaleSlope, ds.RescaleIntercept = slope, intercept
        ds.PixelData = np.ascontiguousarray(stored.T).tobytes()  # rows (j) of columns (i)
        ds.save_as(name, write_like_original=False)


def write_nrrd(path):
    ras = RAS_FROM_LPS @ LPS_FROM_IJK  # stated in RAS to exercise the conversion
    vec = lambda v: "(" + ",".join(repr(float(x)) for x in v) + ")"
    header = ("NRRD0004\ntype: short\ndimension: 3\nspace: right-anterior-superior\n"
              f"sizes: {NX} {NY} {NZ}\n"
              f"space directions: {vec(ras[:3, 0])} {vec(ras[:3, 1])} {vec(ras[:3, 2])}\n"
              "kinds: domain domain domain\nendian: big\nencoding: gzip\n"
              f"space origin: {vec(ras[:3, 3])}\n\n")
    data = VALUES.astype(">i2").tobytes(order="F")  # i fastest
    with open(path, "wb") as out:
        out.write(header.encode("ascii") + gzip.compress(data))


def main():
    folder = sys.argv[1]
    os.makedirs(folder, exist_ok=True)
    write_truth(folder)
    write_nifti(folder)
    write_dicom(os.path.join(folder, "dicom"))
    write_nrrd(os.path.join(folder, "oblique.nrrd"))


if __name__ == "__main__":
    main()
